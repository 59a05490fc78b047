"""dec3d.physics"""
