from ._pegasus import *  # noqa: F401,F403
from . import gym as gym
from .mdp import add_shaping as add_shaping, audit_shaping as audit_shaping, finite_mdp as finite_mdp

__version__: str
