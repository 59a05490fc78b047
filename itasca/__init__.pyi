# Type checkers: `import itasca` is dec3d.itasca (the shim replaces itself by it at import).
from dec3d.itasca import *  # noqa: F401,F403
from dec3d.itasca import (block as block, blockarray as blockarray, contactarray as contactarray,  # noqa: F401
                          fish as fish, gridpointarray as gridpointarray, structure as structure,
                          zonearray as zonearray)
