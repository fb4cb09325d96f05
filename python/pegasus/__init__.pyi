from ._pegasus import *  # noqa: F401,F403
from . import gym as gym
from . import training as training
from .mdp import add_shaping as add_shaping, audit_shaping as audit_shaping, finite_mdp as finite_mdp
from .training import TrainingPlan as TrainingPlan, TrainingStage as TrainingStage, train as train

__version__: str
