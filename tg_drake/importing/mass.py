"""Mass properties of an imported object: mass, centre of mass and inertia in its frame O.

The solid is the one the (repaired) mesh bounds. A closed mesh gives it directly (trimesh's
mass properties). An open or multi-piece mesh gets its holes closed by flat fans for the
integrals (`mesh.hole_caps`; caps of two pieces meeting at a seam cancel); when that does not
give a sensible solid (no volume, or more than its convex hull), the convex hull is used. Each
assumption is a warning.

Mass: the user's `mass` [kg] (the density then follows), or `density` [kg/m³], or the category's
density prior: the median over the shipped library's objects of the category of mass / volume
enclosed by the mesh (`density_prior`, computed from the library at run time).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import trimesh

from tg_drake.errors import ModelError
from tg_drake.importing.mesh import capped_moments
from tg_drake.objects import library_by_category, mesh
from tg_drake.types import CATEGORIES

# A capped solid with more volume than its convex hull by this factor is not a solid (caps that
# cross the object): the hull is used instead. 1 % covers the integrals' rounding.
HULL_SLACK = 1.01


@dataclass(frozen=True)
class MassProperties:
    mass: float  # [kg]
    volume: float  # [m³] of the solid used
    density: float  # [kg/m³] mass / volume
    com: np.ndarray  # (3,) [m]
    inertia: np.ndarray  # (3, 3) [kg·m²] about the COM, the mesh's axes
    solid: str  # "closed mesh" | "holes closed" | "convex hull"
    why: str  # how the mass was decided (for the report)
    warnings: tuple[str, ...]


def _library_density(obj) -> float:
    V, F, _ = mesh(obj)
    vol = capped_moments(np.asarray(V), np.asarray(F))[0]
    return obj.mass / vol


@functools.cache
def density_prior(category: str | None) -> float:
    """[kg/m³] median over the shipped library's objects of `category` (all objects when None)
    of mass / volume enclosed by the object's mesh (a closed bottle's cavity counts)."""
    by_cat = library_by_category()
    if category is not None and category not in by_cat:
        raise ModelError(f"unknown category {category!r}; allowed: {', '.join(CATEGORIES)}",
                         field="category")
    objs = by_cat[category] if category is not None else [o for v in by_cat.values() for o in v]
    return float(np.median([_library_density(o) for o in objs]))


def _from_moments(volume, first, second, density):
    mass = density * volume
    com = first / volume
    J = density * second - mass * np.outer(com, com)  # ∫ (x-c)(x-c)ᵀ dm
    inertia = np.trace(J) * np.eye(3) - J
    return mass, com, 0.5 * (inertia + inertia.T)


def mass_properties(V: np.ndarray, F: np.ndarray, *, watertight: bool, category: str | None,
                    mass: float | None = None, density: float | None = None,
                    file: str | None = None) -> MassProperties:
    """Mass properties of the solid the mesh (V, F) [m] bounds, in the mesh's frame."""
    if mass is not None and density is not None:
        raise ModelError("both mass and density given; allowed: one of them, or neither (the "
                         "category's density prior)", file=file, field="mass")
    for name, value in (("mass", mass), ("density", density)):
        if value is not None and not (np.isfinite(value) and value > 0):
            raise ModelError(f"{name} {value!r}; allowed: a positive number", file=file,
                             field=name)
    warnings = []
    hull = trimesh.convex.convex_hull(V[np.unique(F)])  # of the vertices the triangles use
    hull_volume = float(hull.volume)
    vol, first, second, cap_area = capped_moments(V, F)
    if watertight and vol > 0:
        solid = "closed mesh"
    elif 0 < vol <= HULL_SLACK * hull_volume:
        solid = "holes closed"
        area = float(trimesh.Trimesh(V, F, process=False).area)
        warnings.append(f"open mesh: its holes closed by flat caps ({1e4 * cap_area:.1f} cm², "
                        f"{100 * cap_area / area:.1f} % of its surface) for the mass properties")
    else:
        solid = "convex hull"
        vol, first, second, _ = capped_moments(np.asarray(hull.vertices), np.asarray(hull.faces))
        warnings.append("the mesh bounds no usable solid (open, inside out or self-crossing): "
                        f"mass properties of its convex hull ({1e6 * vol:.0f} cm³), assumed "
                        "solid")
    if not vol > 0:
        raise ModelError("the mesh encloses no volume, nor does its convex hull (a flat "
                         "object); allowed: a solid object's surface", file=file)
    if mass is not None:
        rho, why = mass / vol, f"given: {mass:.4g} kg"
    elif density is not None:
        rho, why = density, f"density given: {density:.4g} kg/m³"
    else:
        rho = density_prior(category)
        what = f"category {category}" if category else "all categories"
        why = (f"density prior of {what}: {rho:.0f} kg/m³ (median mass / mesh volume of the "
               "shipped library's objects)")
        warnings.append(f"no mass or density given: {why}")
    m, com, inertia = _from_moments(vol, first, second, rho)
    if not (np.isfinite(inertia).all() and np.all(np.linalg.eigvalsh(inertia) > 0)):
        raise ModelError("the mass properties are not physical (inertia not positive definite)",
                         file=file)
    return MassProperties(float(m), float(vol), float(rho), com, inertia, solid, why,
                          tuple(warnings))
