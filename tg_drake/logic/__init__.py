"""The probabilistic logic stage (paper section IV): a ProbLog CP-theory (rules/ at the top of the
repository) asked for the category, task and pre-grasp part of one object.

- `tg_drake.logic.observations`: `Observations`, the scene as data for the theory;
- `tg_drake.logic.theory`: where the theory files are, variants (`TheoryConfig`), loading;
- `tg_drake.logic.engine`: `LogicEngine` (compiled once, re-weighted per scene) and
  `reference_query` (plain ProbLog), `LogicAnswer`, `LogicQueryConfig`;
- `tg_drake.logic.circuit`: the compiled SDD as a NumPy circuit;
- `tg_drake.logic.cli`: `tg-drake query`; `tg_drake.logic.bench`: the `logic_scene_ms` figure.

The Drake system is `tg_drake.systems.logic_system.LogicQuerySystem`. Nothing is imported here so
that `tg-drake` builds its parser without loading ProbLog.
"""
