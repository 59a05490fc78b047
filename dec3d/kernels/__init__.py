"""dec3d.kernels"""
