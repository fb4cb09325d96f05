"""The training layer (optimizers/training.hpp) from Python: a plan of optimizer stages run one after another,
the best theta of each the start of the next (thesis §5.3: gradient ascent, then hill climbing from its result),
with one seed for every stage's optimizer, one checkpoint schema for the whole plan and iteration callbacks.

    plan = pegasus.TrainingPlan(seed=7, stages=[
        pegasus.TrainingStage("gradient", pegasus.OptimizerOptions("gradient")),
        pegasus.TrainingStage("refine", pegasus.OptimizerOptions("cmaes"), seeds=pegasus.REFINE_SEED_DOMAINS)])
    theta, summary = pegasus.train(plan, objective)

The fields are the C++ structs' (TrainingStage: name, optimizer, seeds, objective; TrainingPlan: stages, seed,
checkpoint_every, on_checkpoint, resume_from, callbacks). A checkpoint is a dict ("format":
"pegasus.training.checkpoint"); a plan given one as resume_from continues exactly where the plan that wrote it
was, so the result is bit-identical to an uninterrupted run.
"""
from dataclasses import dataclass, field
from typing import Any, Callable, List, Optional

from . import _pegasus


def _default_seeds():
    return _pegasus.SeedDomains()


@dataclass
class TrainingStage:
    """One stage: its name (reports, messages), its optimizer (seeds set by train from the plan's seed and
    `seeds`; checkpointing by the plan; method "none" skips it) and optionally its own objective (a refinement
    on more scenarios, say; None: the one passed to train)."""
    name: str
    optimizer: Any = field(default_factory=lambda: _pegasus.OptimizerOptions())
    seeds: Any = field(default_factory=_default_seeds)
    objective: Optional[Any] = None


@dataclass
class TrainingPlan:
    """Stages run in order. seed: the root of every stage's optimizer seeds. checkpoint_every: optimizer
    iterations between checkpoints (0: none), each passed to on_checkpoint (a dict; write it atomically to
    survive a crash). resume_from: such a checkpoint, to continue. callbacks: callables f(IterationReport) told
    after every iteration of every stage; True or CallbackReturnType.TERMINATE ends the current stage with
    USER_REQUESTED and skips the stages after it."""
    stages: List[TrainingStage] = field(default_factory=list)
    seed: int = 1
    checkpoint_every: int = 0
    on_checkpoint: Optional[Callable[[dict], None]] = None
    resume_from: Optional[dict] = None
    callbacks: List[Callable[[Any], Any]] = field(default_factory=list)


def train(plan: TrainingPlan, objective, theta=None):
    """Runs the plan from theta (None: the spec's initial values) with the GIL released; returns (theta, the
    last stage's best; TrainingSummary). ValueError naming the field (plan.stages[k].optimizer.gradient.max_step,
    plan.checkpoint_every, ...) for a plan that cannot run or a checkpoint that is not this plan's."""
    return _pegasus._train(plan, objective, theta)
