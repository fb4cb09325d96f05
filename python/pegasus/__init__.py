"""Pegasus from Python: PEGASUS policy search (Ng's thesis, ch. 4) and reward shaping (ch. 3).

A thin layer over the C++ library:
  ScenarioSet                       scenario sets (plain, antithetic, stratified, Sobol) as numpy arrays
  VectorizedProblem                 your own simulator and policy in numpy, one Python call per time step for
                                    every (theta, scenario) pair of an evaluation
  LinearPolicy, SigmoidPolicy       built-in policy classes over a batch (computed in C++)
  Bicycle, BicycleProblem, ...      built-in environments; train_bicycle as `pegasus bicycle train`
  OptimizerOptions, solve           every optimizer, Options and Summary with the C++ field names,
                                    checkpoints as dicts
  finite_mdp, audit_shaping         finite MDPs from numpy or scipy.sparse, solvers, shaping and its audit
  gym.GymModel                      Gymnasium-style environments as deterministic models
Results are the C++ library's, bit for bit: the same seed and options give the same figures as the `pegasus`
command line, for any `threads`. Bad arguments raise ValueError naming the argument and what was expected.
"""
from ._pegasus import *  # noqa: F401,F403
from ._pegasus import (BicycleProblem, BoxPolicy, FiniteMdp, FunctionObjective, Objective,  # noqa: F401
                       OptimizerOptions, OptimizerSummary, Parameter, ParameterSpec, ScenarioSet,
                       VectorizedProblem, solve)

# The pure-Python parts load on first use (PEP 562), so that `import pegasus` does not import numpy: the extension
# itself imports numpy only when it first exchanges an array.
_LAZY = {"finite_mdp": "mdp", "add_shaping": "mdp", "audit_shaping": "mdp", "gym": None}


def __getattr__(name):
    if name not in _LAZY:
        raise AttributeError(f"module 'pegasus' has no attribute '{name}'")
    import importlib
    module = importlib.import_module(f".{_LAZY[name] or name}", __name__)
    value = module if _LAZY[name] is None else getattr(module, name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(list(globals()) + list(_LAZY))

__version__ = "0.1.0"
