"""Where the shipped models are: the `tg_drake_models` package (models/ in the source tree).

Drake resolves ``package://tg_drake_models/...`` through the package's package.xml; `make_parser`
gives a parser that knows it. The station, the planning plant and the tests parse through it.
"""

from __future__ import annotations

import functools
import importlib.resources

from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant


@functools.cache
def models_root() -> str:
    """The folder of the tg_drake_models package (models/ in the source tree)."""
    return str(importlib.resources.files("tg_drake_models"))


def make_parser(plant: MultibodyPlant) -> Parser:
    """A parser that resolves package://tg_drake_models/... (and nothing from the internet)."""
    parser = Parser(plant)
    parser.package_map().AddPackageXml(f"{models_root()}/package.xml")
    return parser
