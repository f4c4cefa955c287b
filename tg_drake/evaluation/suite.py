"""Evaluation suites: YAML files (scenarios/suites/) that stand for the paper's datasets (VI-A).

A suite is of one kind:

- "synthetic": perfect observations of library objects (the paper's S_SYN): the object's parts with
  probability 1, its pose and containment; no rendering, no physics. The logic and the kernel prior
  (on a labelled sampling of the mesh, leave-one-object-out) are queried.
- "perceived": every case rendered (depth ray cast from the default camera's viewpoint) and
  perceived; the perceived description gives the observations in the paper's settings (S_REAL_semi:
  true pose, detected parts with probability 1; S_REAL: perceived pose likelihood, confident parts
  kept; S_REAL_noisy: perceived pose likelihood and part likelihoods).
- "executed": scenarios run end to end in simulation (`tg_drake.run.run_scenario`), in variants
  "pipeline" (kernel prior + logic + DGI), "pipeline_uniform" (uniform category prior) and "local"
  (hypotheses ranked by the DGI's P(grasp | local shape) alone) and "random_part" (a part drawn
  uniformly, seeded by the case, among those with a pre-grasp hypothesis; its grasp by P(grasp |
  local shape)): S_GRASP and S_ROBOT, the single-object sweep (dataset "sweep", ours) and the task
  suites (dataset "tasks", ours: each task executed and judged by physics).

An executed suite's `task_scene` is what the task needs in every case's scene beside the target
(`TaskScene`: a bowl to pour into, surfaces, the contents' model, a dispenser, the run's duration);
each case's scenario is validated when the suite loads. Every record says which side of the
object-wise split (tg_drake.evaluation.split) its target is on (`split`: train / held_out).

Cases come from a `generator` (objects × poses × containments × yaws × tasks, or `sample` cases
drawn from that product with the suite's seed, moved and turned at random) or from `scenes`
(explicit multi-object scenes, each with variations). Ground truth is set-valued, as in the paper:
a generated case takes its task set and its acceptable pre-grasp parts from the tables of the
`ground_truth` file named by the suite (each table says where it comes from); a scene carries its
own (`task.ground_truth`, with its reason). `load_suite` checks every name and raises ScenarioError
naming the file, the field and the allowed values.
"""

import dataclasses
import functools
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml
from pydrake.common.yaml import yaml_load_typed

from tg_drake.errors import ScenarioError, unknown_name
from tg_drake.evaluation.split import load_split
from tg_drake.objects import get_object, load_library
from tg_drake.scenario import (
    ContentsConfig,
    DispenserConfig,
    ObjectPlacement,
    Scenario,
    SurfaceConfig,
    TaskConfig,
    add_object_libraries,
    validate,
)
from tg_drake.types import CATEGORIES, CONTAINMENTS, PART_LABELS, POSES, TASKS

KINDS = ("synthetic", "perceived", "executed")
SETTINGS = ("semi", "real", "noisy")  # perceived suites: the paper's S_REAL_semi / S_REAL / noisy
VARIANTS = ("pipeline", "pipeline_uniform", "local", "random_part")  # executed suites
# dataset label → the paper's name (rows of the section VI tables).
DATASETS = {"syn": "S_SYN", "real_semi": "S_REAL_semi", "real": "S_REAL",
            "real_noisy": "S_REAL_noisy", "grasp": "S_GRASP_noisy", "robot": "S_ROBOT",
            "sweep": "Sweep", "tasks": "Tasks"}
OURS = ("sweep", "tasks")  # datasets of ours, not analogues of the paper's (no paper figures)
DATASET_OF_SETTING = {"semi": "real_semi", "real": "real", "noisy": "real_noisy"}
CLASSES = ("dish", "kitchen_container", "canister", "tool")  # rules/README.md tables 1 and 5


@dataclass
class TaskTable:
    """The tasks an object affords: category → containment → tasks."""

    reason: str = ""  # where the sets come from
    table: dict[str, dict[str, list[str]]] = field(default_factory=dict)


@dataclass
class PartTable:
    """Acceptable pre-grasp parts: class (or category) → task → condition → parts. A condition is
    "any", a pose, a containment, or "<pose>_<containment>"; the most specific one that matches is
    used, a category's rows before its class's. An empty list: no grasp is acceptable (the case is
    left out of the pre-grasp table)."""

    reason: str = ""
    classes: dict[str, str] = field(default_factory=dict)  # category → class (CLASSES)
    table: dict[str, dict[str, dict[str, list[str]]]] = field(default_factory=dict)


@dataclass
class GroundTruthTables:
    tasks: TaskTable = field(default_factory=TaskTable)
    parts: PartTable = field(default_factory=PartTable)


@dataclass
class Generator:
    """Cases as a product: objects × poses × containments × yaws (× tasks for executed suites)."""

    objects: list[str] = field(default_factory=lambda: ["all"])  # library ids, categories, "all"
    exclude: list[str] = field(default_factory=list)  # library ids left out
    poses: list[str] = field(default_factory=list)  # [] = every pose that suits the object
    containments: list[str] = field(default_factory=lambda: ["empty"])  # "full" is applied only
    # where the object holds water in that pose: a container upright, a closed canister sideways
    yaws: list[float] = field(default_factory=lambda: [0.0])  # [deg] about the table normal
    xy: list[float] = field(default_factory=lambda: [0.0, 0.0])  # [m] in the table frame
    tasks: list[str] = field(default_factory=list)  # executed: the tasks run, those of the
    # case's ground-truth set only; [] = all of them. Synthetic and perceived cases query every
    # ground-truth task.
    place_xy: list[float] = field(default_factory=lambda: [0.0, -0.3])  # [m] table frame
    max_grasp_width: float = math.inf  # [m] objects whose every part is wider are left out
    sample: int = 0  # 0: every case of the product; N > 0: N cases drawn from it with the suite's
    # seed, the chosen objects' categories in turn (an object, pose, containment, yaw and task each)
    xy_spread: list[float] = field(default_factory=lambda: [0.0, 0.0])  # [m] a drawn case's xy
    # is `xy` plus a uniform offset within ± these (table frame)
    yaw_spread: float = 0.0  # [deg] a drawn case's yaw is one of `yaws` plus a uniform offset in
    # [0, yaw_spread)


@dataclass
class Variation:
    """One run of a scene: every object shifted and turned, optionally another target or task."""

    shift: list[float] = field(default_factory=lambda: [0.0, 0.0])  # [m] added to each xy
    yaw: float = 0.0  # [deg] added to each object's yaw
    target: str = ""  # instance name; "" = the scene's target
    task: str = ""  # "" = the scene's task
    parts: list[str] = field(default_factory=list)  # ground-truth parts when `task` changes them


@dataclass
class Scene:
    name: str = ""
    objects: list[ObjectPlacement] = field(default_factory=list)
    task: TaskConfig = field(default_factory=TaskConfig)
    variations: list[Variation] = field(default_factory=list)  # [] = the scene once


@dataclass
class TaskScene:
    """What a task needs in the scene of every case of an executed suite, beside the target (the
    scenario's fields of the same names; tg_drake.scenario)."""

    objects: list[ObjectPlacement] = field(default_factory=list)  # more objects, e.g. the bowl
    # pourOut pours into; their instance names must differ from the targets'
    surfaces: list[SurfaceConfig] = field(default_factory=list)  # p&pOn: boxes on the table
    place_on: str = ""  # p&pOn: task.place_on (the surface's name)
    pour_into: str = ""  # pourOut: task.pour_into (the instance name of one of `objects`)
    contents: ContentsConfig | None = None  # None: the scenario's default (the mass model)
    dispenser: DispenserConfig | None = None  # pourIn: the dispenser of spheres
    simulation_duration: float = 0.0  # [s] upper bound of a run; 0: the scenario's default

    def apply(self, scenario: Scenario) -> Scenario:
        """`scenario` with this task scene added (in place; returned)."""
        scenario.objects = list(scenario.objects) + [dataclasses.replace(p)
                                                     for p in self.objects]
        scenario.surfaces = [dataclasses.replace(s) for s in self.surfaces]
        scenario.task.place_on = self.place_on
        scenario.task.pour_into = self.pour_into
        if self.contents is not None:
            scenario.contents = dataclasses.replace(self.contents)
        if self.dispenser is not None:
            scenario.dispenser = dataclasses.replace(self.dispenser)
        if self.simulation_duration:
            scenario.simulation_duration = self.simulation_duration
        return scenario


@dataclass
class Suite:
    name: str = ""
    description: str = ""
    kind: str = ""  # one of KINDS
    dataset: str = ""  # one of DATASETS (perceived suites: one per setting, from `settings`)
    settings: list[str] = field(default_factory=list)  # perceived: SETTINGS entries
    variants: list[str] = field(default_factory=lambda: ["pipeline"])  # executed: VARIANTS
    kernel_T: int = 13  # propagation-kernel iterations of the prior fed to the PLM (paper: 13
    # on S_SYN, 3 on S_REAL); Label fractions is T = 0.
    ground_truth: str = ""  # file of GroundTruthTables, relative to the suite file
    generator: Generator | None = None
    scenes: list[Scene] = field(default_factory=list)
    seed: int = 0  # seeds the kernel prior's samplings
    object_libraries: list[str] = field(default_factory=list)  # user object library folders
    # (relative to the suite file) whose objects the generator and the scenes may name
    task_scene: TaskScene | None = None  # executed: what every case's scene adds for its task


@dataclass(frozen=True)
class Truth:
    category: str
    tasks: tuple[str, ...]  # afforded tasks
    parts: dict  # task → acceptable parts (empty: no acceptable grasp)
    reason: str


@dataclass(frozen=True)
class Case:
    """One job of a sweep: everything a worker needs, picklable."""

    key: str  # unique across the suites of a sweep
    suite: str
    kind: str
    dataset: str
    objects: tuple[ObjectPlacement, ...]
    target: str  # instance name of the target
    task: str  # the task given to an executed run ("" = inferred); unused otherwise
    place_xy: tuple[float, float]
    truth: Truth
    variant: str = ""  # executed
    settings: tuple[str, ...] = ()  # perceived
    kernel_T: int = 13
    seed: int = 0
    theory: str = "specific"  # the model variant standing in for "specific" (PLM, pipeline)
    object_libraries: tuple[str, ...] = ()  # absolute folders of the user libraries it names
    task_scene: TaskScene | None = None  # executed: what the scene adds for the task

    @property
    def target_placement(self) -> ObjectPlacement:
        return next(p for p in self.objects if p.instance_name == self.target)

    def scenario(self) -> Scenario:
        """The case's scene as a scenario (the default pipeline; not validated): its objects, its
        task and the suite's task scene."""
        scenario = Scenario(objects=[dataclasses.replace(p) for p in self.objects],
                            task=TaskConfig(target=self.target, task=self.task,
                                            place_xy=list(self.place_xy)),
                            object_libraries=list(self.object_libraries))
        return self.task_scene.apply(scenario) if self.task_scene is not None else scenario

    def meta(self) -> dict:
        """The case as JSON (part of every record it gives)."""
        p = self.target_placement
        return {"suite": self.suite, "kind": self.kind, "dataset": self.dataset,
                "variant": self.variant, "object": p.id, "split": split_role(p.id),
                "pose": p.pose, "yaw": p.yaw,
                "containment": p.containment, "object_parts": list(get_object(p.id).parts),
                "n_objects": len(self.objects),
                "task_given": self.task, "theory": self.theory, "truth": {
                    "category": self.truth.category, "tasks": list(self.truth.tasks),
                    "parts": {t: list(v) for t, v in self.truth.parts.items()},
                    "reason": self.truth.reason}}


@functools.cache
def _split():
    return load_split()


def split_role(obj_id: str) -> str | None:
    """"train" or "held_out": the object's side of the object-wise split
    (scenarios/suites/split.yaml); None for an object in none of its sets (a user's)."""
    try:
        return _split().role(obj_id)
    except ScenarioError:
        return None


def _load_typed(cls, path: Path):
    if not path.is_file():
        raise ScenarioError("no such suite file", file=str(path))
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        raise ScenarioError(f"not valid YAML: {getattr(e, 'problem', e)}", file=str(path),
                            line=mark.line + 1 if mark is not None else None) from None
    if not isinstance(data, dict):
        raise ScenarioError("a suite file holds a mapping (name, kind, dataset, generator or "
                            "scenes, ...)", file=str(path))
    try:
        return yaml_load_typed(schema=cls, data=path.read_text())
    except (RuntimeError, ValueError, TypeError, KeyError, AssertionError) as e:
        raise ScenarioError(" ".join(str(e).split()), file=str(path)) from None


def load_ground_truth(path: Path) -> GroundTruthTables:
    """The ground-truth tables of a file, every name checked."""
    gt = _load_typed(GroundTruthTables, path)
    where = str(path)
    for category, rows in gt.tasks.table.items():
        if category not in CATEGORIES:
            raise unknown_name("category", category, CATEGORIES, error=ScenarioError,
                               file=where, field="tasks.table")
        for containment, tasks in rows.items():
            if containment not in CONTAINMENTS:
                raise unknown_name("containment", containment, CONTAINMENTS,
                                   error=ScenarioError, file=where,
                                   field=f"tasks.table.{category}")
            for t in tasks:
                if t not in TASKS:
                    raise unknown_name("task", t, TASKS, error=ScenarioError, file=where,
                                       field=f"tasks.table.{category}.{containment}")
    for category, cls in gt.parts.classes.items():
        if category not in CATEGORIES:
            raise unknown_name("category", category, CATEGORIES, error=ScenarioError,
                               file=where, field="parts.classes")
        if cls not in CLASSES:
            raise unknown_name("class", cls, CLASSES, error=ScenarioError, file=where,
                               field=f"parts.classes.{category}")
    conditions = {"any", *POSES, *CONTAINMENTS, *(f"{p}_{c}" for p in POSES for c in CONTAINMENTS)}
    for cls, by_task in gt.parts.table.items():
        if cls not in CLASSES and cls not in CATEGORIES:
            raise unknown_name("class or category", cls, CLASSES + CATEGORIES,
                               error=ScenarioError, file=where, field="parts.table")
        for task, by_condition in by_task.items():
            if task not in TASKS:
                raise unknown_name("task", task, TASKS, error=ScenarioError, file=where,
                                   field=f"parts.table.{cls}")
            for condition, parts in by_condition.items():
                f = f"parts.table.{cls}.{task}"
                if condition not in conditions:
                    raise unknown_name("condition", condition, sorted(conditions),
                                       error=ScenarioError, file=where, field=f)
                for part in parts:
                    if part not in PART_LABELS:
                        raise unknown_name("part", part, PART_LABELS, error=ScenarioError,
                                           file=where, field=f"{f}.{condition}")
    if not gt.tasks.reason or not gt.parts.reason:
        raise ScenarioError("each ground-truth table needs its `reason` (where the sets come "
                            "from)", file=where, field="tasks.reason / parts.reason")
    return gt


def truth_of(gt: GroundTruthTables, obj, pose: str, containment: str, where: str) -> Truth:
    """Task set and per-task acceptable parts of a library object in a pose and containment
    (`where`: the ground-truth file)."""
    rows = gt.tasks.table.get(obj.category)
    if rows is None or containment not in rows:
        raise ScenarioError(f"the task table has no row for {obj.category} ({containment})",
                            file=where, field="tasks.table")
    cls = gt.parts.classes.get(obj.category)
    if cls is None:
        raise ScenarioError(f"no class for category {obj.category!r}", file=where,
                            field="parts.classes")
    parts = {}
    for task in rows[containment]:
        # A category's own rows (e.g. the upside-down pan) come before its class's.
        for key in (obj.category, cls):
            by_condition = gt.parts.table.get(key, {}).get(task, {})
            condition = next((c for c in (f"{pose}_{containment}", pose, containment, "any")
                              if c in by_condition), None)
            if condition is not None:
                parts[task] = tuple(p for p in by_condition[condition] if p in obj.parts)
                break
        else:
            raise ScenarioError(f"no acceptable parts for {obj.category} (class {cls}), task "
                                f"{task}, pose {pose}, {containment}", file=where,
                                field=f"parts.table.{cls}.{task}")
    return Truth(obj.category, tuple(rows[containment]), parts,
                 f"{Path(where).name}: rules/README.md Table 3 (tasks), Table 5 (parts)")


def _can_hold_water(obj, pose: str) -> bool:
    """Full applies to containers upright, and to closed canisters (bottle, can) sideways."""
    return obj.is_container and (pose == "upright" or
                                 (pose == "sideways" and obj.category in ("bottle", "can")))


def _generated(suite: Suite, gt: GroundTruthTables, where: str, gt_where: str) -> list[Case]:
    g = suite.generator
    library = dict(load_library())
    for folder in suite.object_libraries:  # registered (and checked) by load_suite
        library.update(load_library(folder))
    chosen = []
    for name in g.objects:
        if name == "all":
            chosen += list(library.values())
        elif name in CATEGORIES:
            chosen += [o for o in library.values() if o.category == name]
        elif name in library:
            chosen.append(library[name])
        else:
            raise unknown_name("object or category", name, ["all", *CATEGORIES, *library],
                               error=ScenarioError, file=where, field="generator.objects")
    for name in g.exclude:
        if name not in library:
            raise unknown_name("object", name, list(library), error=ScenarioError, file=where,
                               field="generator.exclude")
    for pose in g.poses:
        if pose not in POSES:
            raise unknown_name("pose", pose, POSES, error=ScenarioError, file=where,
                               field="generator.poses")
    for c in g.containments:
        if c not in CONTAINMENTS:
            raise unknown_name("containment", c, CONTAINMENTS, error=ScenarioError, file=where,
                               field="generator.containments")
    for t in g.tasks:
        if t not in TASKS:
            raise unknown_name("task", t, TASKS, error=ScenarioError, file=where,
                               field="generator.tasks")
    if g.sample < 0:
        raise ScenarioError(f"sample is a number of cases (0 = the whole product), got "
                            f"{g.sample}", file=where, field="generator.sample")
    if not g.sample and (any(g.xy_spread) or g.yaw_spread):
        raise ScenarioError("xy_spread and yaw_spread vary drawn cases only: set `sample`",
                            file=where, field="generator.sample")
    seen, cases = set(), []
    for obj in chosen:
        if obj.id in seen or obj.id in g.exclude:
            continue
        if obj.category is None:
            raise ScenarioError(f"{obj.id} has no category, the ground truth a generated case "
                                "needs (import it with a category)", file=where,
                                field="generator.objects")
        seen.add(obj.id)
        if min(obj.grasp_widths.values(), default=math.inf) > g.max_grasp_width:
            continue
        for pose in obj.poses:
            if g.poses and pose not in g.poses:
                continue
            for containment in g.containments:
                if containment == "full" and not _can_hold_water(obj, pose):
                    continue
                truth = truth_of(gt, obj, pose, containment, gt_where)
                for yaw in g.yaws:
                    placement = ObjectPlacement(id=obj.id, pose=pose, xy=list(g.xy), yaw=yaw,
                                                containment=containment)
                    name = f"{obj.id}_{pose}_{containment}" + (f"_y{yaw:g}" if len(g.yaws) > 1
                                                               else "")
                    tasks = ([t for t in truth.tasks if not g.tasks or t in g.tasks]
                             if suite.kind == "executed" else [""])
                    for task in tasks:
                        for variant in (suite.variants if suite.kind == "executed" else [""]):
                            key = f"{suite.name}/{name}" + (f"_{task}" if task else "") + (
                                f"@{variant}" if variant else "")
                            cases.append(Case(
                                key, suite.name, suite.kind, suite.dataset, (placement,),
                                placement.instance_name, task, tuple(g.place_xy), truth,
                                variant, tuple(suite.settings), suite.kernel_T, suite.seed,
                                object_libraries=tuple(suite.object_libraries),
                                task_scene=suite.task_scene))
    return _drawn(suite, cases, library) if g.sample else cases


def _drawn(suite: Suite, product: list[Case], library) -> list[Case]:
    """`generator.sample` cases drawn from the product with the suite's seed: categories in turn,
    then a case of that category (its variants together), moved by the spreads."""
    g = suite.generator
    rng = np.random.default_rng(suite.seed)
    by_scenario: dict[str, list[Case]] = {}
    for c in product:  # a scenario's variants side by side
        by_scenario.setdefault(c.key.split("@")[0], []).append(c)
    by_category: dict[str, list[list[Case]]] = {}
    for variants in by_scenario.values():
        category = library[variants[0].target_placement.id].category
        by_category.setdefault(category, []).append(variants)
    categories = [c for c in CATEGORIES if c in by_category]
    cases = []
    for i in range(g.sample):
        variants = by_category[categories[i % len(categories)]]
        chosen = variants[int(rng.integers(len(variants)))]
        p = chosen[0].target_placement
        dx, dy = (rng.uniform(-1.0, 1.0, size=2) * np.asarray(g.xy_spread, dtype=float)).tolist()
        placement = dataclasses.replace(
            p, xy=[round(p.xy[0] + dx, 3), round(p.xy[1] + dy, 3)],
            yaw=round(p.yaw + float(rng.uniform(0.0, g.yaw_spread)), 1))
        name = f"{i:03d}_{p.id}_{p.pose}_{p.containment}" + (f"_{chosen[0].task}"
                                                              if chosen[0].task else "")
        for c in chosen:
            cases.append(dataclasses.replace(
                c, key=f"{suite.name}/{name}" + (f"@{c.variant}" if c.variant else ""),
                objects=(placement,)))
    return cases


def _scenes(suite: Suite, where: str) -> list[Case]:
    cases = []
    for i, scene in enumerate(suite.scenes):
        f = f"scenes[{i}]"
        if not scene.name:
            raise ScenarioError("a scene needs a `name`", file=where, field=f + ".name")
        for j, variation in enumerate(scene.variations or [Variation()]):
            objects = [dataclasses.replace(
                p, xy=[p.xy[0] + variation.shift[0], p.xy[1] + variation.shift[1]],
                yaw=p.yaw + variation.yaw) for p in scene.objects]
            task = TaskConfig(target=variation.target or scene.task.target,
                              task=variation.task or scene.task.task,
                              place_xy=list(scene.task.place_xy),
                              ground_truth=scene.task.ground_truth)
            for part in list(variation.parts) + list(scene.task.ground_truth.parts):
                if part not in PART_LABELS:  # named by the suite's field, before the scenario's
                    raise unknown_name("part", part, PART_LABELS, error=ScenarioError,
                                       file=where, field=f + ".task.ground_truth.parts")
            scenario = Scenario(objects=objects, task=task,
                                object_libraries=list(suite.object_libraries))
            try:  # mesh entries are imported here (cached), relative to the suite's folder
                validate(scenario, where=where, base_dir=Path(where).parent)
            except ScenarioError as e:
                raise ScenarioError(e.message, file=where,
                                    field=f"{f}.variations[{j}] {e.field or ''}".strip()) from None
            target = scenario.target_placement()
            gt = task.ground_truth
            category = gt.category or get_object(target.id).category
            if category is None:
                raise ScenarioError(f"{target.id} has no category: give the scene's "
                                    "task.ground_truth.category", file=where,
                                    field=f + ".task.ground_truth.category")
            parts = list(variation.parts) if variation.task else list(gt.parts)
            if not gt.reason:
                raise ScenarioError("a scene's ground truth needs its `reason`", file=where,
                                    field=f + ".task.ground_truth.reason")
            truth = Truth(category, tuple(gt.tasks), {task.task: tuple(parts)} if task.task
                          else {}, gt.reason)
            for variant in (suite.variants if suite.kind == "executed" else [""]):
                key = f"{suite.name}/{scene.name}_{j:02d}" + (f"@{variant}" if variant else "")
                cases.append(Case(key, suite.name, suite.kind, suite.dataset, tuple(objects),
                                  target.instance_name, task.task, tuple(task.place_xy), truth,
                                  variant, tuple(suite.settings), suite.kernel_T, suite.seed,
                                  object_libraries=tuple(suite.object_libraries),
                                task_scene=suite.task_scene))
    return cases


def _check_task_scenes(suite: Suite, cases: list[Case], where: str) -> None:
    """Every case's scene with the suite's task scene validated (once per scenario, whatever its
    variant): a surface under the target, a bowl where the target stands, a container whose
    cavity cannot hold the spheres is named with the case."""
    if suite.kind != "executed":
        raise ScenarioError("a task scene is for executed suites", file=where,
                            field="task_scene")
    if suite.task_scene.simulation_duration < 0 or not math.isfinite(
            suite.task_scene.simulation_duration):
        raise ScenarioError(f"simulation_duration must be ≥ 0 and finite [s] (0: the "
                            f"scenario's default), got {suite.task_scene.simulation_duration}",
                            file=where, field="task_scene.simulation_duration")
    seen = set()
    for case in cases:
        name = case.key.split("@")[0]
        if name in seen:
            continue
        seen.add(name)
        try:
            validate(case.scenario(), where=where, base_dir=Path(where).parent)
        except ScenarioError as e:
            raise ScenarioError(f"case {name}: {e.message}", file=where,
                                field=f"task_scene ({e.field})" if e.field else "task_scene"
                                ) from None


def load_suite(path: "str | Path") -> "tuple[Suite, list[Case]]":
    """A suite file and the cases it stands for, every name checked."""
    path = Path(path)
    where = str(path)
    suite = _load_typed(Suite, path)
    if not suite.name:
        suite.name = path.stem
    if suite.kind not in KINDS:
        raise unknown_name("suite kind", suite.kind, KINDS, error=ScenarioError, file=where,
                           field="kind")
    if suite.kind == "perceived":
        if not suite.settings:
            raise ScenarioError("a perceived suite names its settings; allowed: "
                                + ", ".join(SETTINGS), file=where, field="settings")
        for s in suite.settings:
            if s not in SETTINGS:
                raise unknown_name("setting", s, SETTINGS, error=ScenarioError, file=where,
                                   field="settings")
    elif suite.dataset not in DATASETS:
        raise unknown_name("dataset", suite.dataset, list(DATASETS), error=ScenarioError,
                           file=where, field="dataset")
    if suite.kind == "executed":
        for v in suite.variants:
            if v not in VARIANTS:
                raise unknown_name("variant", v, VARIANTS, error=ScenarioError, file=where,
                                   field="variants")
    if not 0 <= suite.kernel_T <= 15:
        raise ScenarioError(f"kernel_T must lie in 0..15, got {suite.kernel_T}", file=where,
                            field="kernel_T")
    suite.object_libraries = add_object_libraries(suite.object_libraries, where=where,
                                                  base_dir=path.parent)
    if (suite.generator is None) == (not suite.scenes):
        raise ScenarioError("a suite has either a `generator` or `scenes`, not "
                            + ("both" if suite.scenes else "neither"), file=where)
    if suite.generator is not None:
        if not suite.ground_truth:
            raise ScenarioError("a generated suite names its `ground_truth` tables file",
                                file=where, field="ground_truth")
        gt = load_ground_truth(path.parent / suite.ground_truth)
        cases = _generated(suite, gt, where, str(path.parent / suite.ground_truth))
    else:
        if suite.kind != "executed":
            raise ScenarioError("scenes are for executed suites; a synthetic or perceived suite "
                                "uses a generator", file=where, field="scenes")
        cases = _scenes(suite, where)
    if not cases:
        raise ScenarioError("the suite has no cases (every object filtered out?)", file=where)
    if suite.task_scene is not None:
        _check_task_scenes(suite, cases, where)
    keys = [c.key for c in cases]
    if len(set(keys)) != len(keys):
        dup = sorted({k for k in keys if keys.count(k) > 1})
        raise ScenarioError(f"cases with the same name: {', '.join(dup[:5])}", file=where)
    return suite, cases
