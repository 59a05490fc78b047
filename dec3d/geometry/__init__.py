"""dec3d.geometry"""
