"""dec3d.lang"""
