"""dec3d.model"""
