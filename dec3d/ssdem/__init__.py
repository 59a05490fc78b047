"""dec3d ssdem: static distinct element slope stability with Winkler springs.

After the SSDEM MSc thesis (shared/seeds/004_47a079be8dc4bc3f.txt) with the
formulation rebuilt in shared/seeds/ERRATA.md.  Layout, one idea per module:

    model.py      arrays of a problem (blocks, interfaces, settings)
    geometry.py   polygons, checks, shared edges
    soil.py       profile, layers, water, surcharges (TOML input)
    mesh.py       grid and slip-surface block meshes;  build.py  properties and loads
    assemble.py   interface stiffness and sparse assembly
    springs.py    tension cut-off and secant Mohr-Coulomb law
    linsolve.py   sparse factorisation with the pivot (instability) test
    solve.py      load steps, secant iteration, removal of unstable blocks
    safety.py     interface FS, yield, failure surface, global FS
    bishop.py     Bishop's simplified method and circle search
    reduction.py  strength-reduction factor of safety (--strength-reduction)
    readers/      Appendix A and TOML inputs;  report.py, plot.py  outputs
    analysis.py   one run end to end;  cli.py  `dec3d ssdem`;  verify.py  `dec3d verify` hook
"""
