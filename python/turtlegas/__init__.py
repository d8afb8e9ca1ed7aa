# SPDX-License-Identifier: MIT
"""turtlegas in process (docs/python.md).

    import turtlegas
    world = turtlegas.World.load("worlds/gas_box.json")
    world.run(until=2.0)

turtlegas.client is the network client of `turtlegas serve` (docs/protocol.md).
"""

from ._turtlegas import Event, World, WorldError
from . import controllers, programs
from .vec import VecWorld

__all__ = ["Event", "VecWorld", "World", "WorldError", "controllers", "programs"]
