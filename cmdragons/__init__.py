"""cmdragons: a RoboCup small-size team after the CMDragons thesis, and its simulator."""

import os as _os

# numba's OpenMP worker threads spin while they wait; on a 2-core machine shared with another
# stage (or another process of a distributed run) that spinning costs a frame 10x its time.
# Passive waiting costs ~10% when the machine is quiet. A user's own setting wins.
_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
