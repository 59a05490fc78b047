"""dec3d.commands"""
