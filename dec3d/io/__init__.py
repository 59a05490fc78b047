"""dec3d.io"""
