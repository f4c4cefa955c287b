"""Object import (issue 18): any mesh a user brings → an object of a library folder in the shipped
library's format. A core: it never imports the Drake systems framework, the station or evaluation.

    from tg_drake.importing import ImportOptions, import_object
    result = import_object("blue_mug.obj", ImportOptions(category="cup"), Path("my_objects"))
    print(result.report)

Modules: source (what the user named → mesh file), mesh (load, units, up axis, repair), frame
(object frame, part labels, dimensions), mass, poses (stable resting poses), collision (convex
decomposition), library (the files; import_object, import_cached), report, cli.
"""

from tg_drake.importing.library import ImportOptions, ImportResult, import_cached, import_object

__all__ = ["ImportOptions", "ImportResult", "import_cached", "import_object"]
