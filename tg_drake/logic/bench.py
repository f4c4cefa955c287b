"""Speed figure of the logic module: `logic_scene_ms`.

All three queries (category, task, pre-grasp part) of one scene, the paper's Fig. 1 cup with the
task inferred, on the specific theory compiled once (the compile is not timed; it runs once per
process). Reference: plain ProbLog on the same scene, the program ground, compiled and evaluated
once per query (`tg_drake.logic.engine.reference_query`), as a user of ProbLog would ask it.
"""

from __future__ import annotations

from tg_drake.bench import Figure, figure, median_time
from tg_drake.logic.engine import LogicEngine, reference_query
from tg_drake.logic.observations import Observations
from tg_drake.logic.theory import TheoryConfig, rules_dir


def logic_scene_ms() -> Figure:
    """Milliseconds for the three queries of one scene (median of 200; reference median of 5)."""
    obs = Observations.from_file(rules_dir() / "examples" / "fig1_cup.yaml")
    config = TheoryConfig()
    engine = LogicEngine(config)
    ours = median_time(lambda: engine.query(obs), repeats=200, warmup=5)
    reference = median_time(lambda: reference_query(obs, config), repeats=5)
    return figure(ours * 1e3, "ms",
                  "plain ProbLog: the scene's program ground, compiled (SDD) and evaluated once "
                  "per query, 3 queries", reference * 1e3)
