"""Object import (issue 18): any mesh a user brings → an object of a library folder in the shipped
library's format. A core: it never imports the Drake systems framework, the station or evaluation.

    from tg_drake.importing import ImportOptions, import_object
    result = import_object("blue_mug.obj", ImportOptions(category="cup"), Path("my_objects"))
    print(result.report)

Modules: source (what the user named → mesh file), mesh (load, units, up axis, repair), frame
(object frame, part labels, dimensions), mass, poses (stable resting poses), collision (convex
decomposition), library (the files; import_object, import_cached), report, cli.

The names below load tg_drake.importing.library on first use, so that `tg-drake --help`, which
imports tg_drake.importing.cli, does not import trimesh, CoACD and pydrake.
"""

from __future__ import annotations

import importlib

__all__ = ["ImportOptions", "ImportResult", "import_cached", "import_object"]


def __getattr__(name: str):
    if name in __all__:
        return getattr(importlib.import_module("tg_drake.importing.library"), name)
    raise AttributeError(f"module 'tg_drake.importing' has no attribute {name!r}")
