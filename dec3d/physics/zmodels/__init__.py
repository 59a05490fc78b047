"""Host files of the zone models, one per kernel in ``dec3d/kernels/zmodels`` (registry:
``dec3d.physics.cmodels``)."""
