"""A user object library made in a temporary folder from a shipped object's files (tests only)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

from tg_drake.objects import library_path, load_library


def copy_object(src_id: str, new_id: str, out_dir: Path, *, derived: bool = True,
                **overrides) -> Path:
    """Writes `out_dir`/<new_id>/ with `src_id`'s mesh, labels and SDF under the new id and adds
    its entry (the shipped one, plus `overrides` and stable poses made from its named poses) to
    `out_dir`/library.yaml. Returns out_dir."""
    src = load_library()[src_id]
    entry = yaml.safe_load(library_path().read_text())["objects"][src_id]
    folder = out_dir / new_id
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{new_id}.obj").write_text(src.mesh_path.read_text())
    np.save(folder / f"{new_id}_parts.npy", np.load(src.parts_path))
    (folder / f"{new_id}.sdf").write_text(src.sdf_path.read_text().replace(src_id, new_id))
    if derived:
        n = len(entry["poses"])
        entry["stable_poses"] = [dict(pose=name, probability=round(1.0 / (k + 2), 3), **v)
                                 for k, (name, v) in enumerate(entry["poses"].items())][:n]
        entry["labels"] = "derived"
        entry["source"] = {"file": f"{src_id}.obj", "units": "m", "up_axis": "z"}
    entry.update(overrides)
    path = out_dir / "library.yaml"
    data = yaml.safe_load(path.read_text()) if path.is_file() else {"objects": {}}
    data["objects"][new_id] = entry
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return out_dir
