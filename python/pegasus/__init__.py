"""Pegasus from Python: PEGASUS policy search (Ng's thesis, ch. 4) and reward shaping (ch. 3).

A thin layer over the C++ library:
  ScenarioSet                       scenario sets (plain, antithetic, stratified, Sobol) as numpy arrays
  VectorizedProblem                 your own simulator and policy in numpy, one Python call per time step for
                                    every (theta, scenario) pair of an evaluation
  LinearPolicy, SigmoidPolicy       built-in policy classes over a batch (computed in C++)
  Bicycle, BicycleProblem, ...      built-in environments; train_bicycle as `pegasus bicycle train`
  Aircraft, LearnedHeliModel        the ground-truth helicopter and the identified model as batch models;
  HoverProblem, train_hover         U-hat of the hover policy on either, and `pegasus heli hover`'s training
  HeliPolicy                        helicopter policy files: controls for a batch of states
  OptimizerOptions, solve           every optimizer (gradient, hill-climb, exhaustive, NLopt, cmaes, ars),
                                    Options and Summary with the C++ field names, checkpoints as dicts
  TrainingPlan, TrainingStage,      the training layer: stages, seeds, one checkpoint schema, callbacks
  train
  finite_mdp, audit_shaping         finite MDPs from numpy or scipy.sparse, solvers, shaping and its audit
  gym.GymModel                      Gymnasium-style environments as deterministic models
Results are the C++ library's, bit for bit: the same seed and options give the same figures as the `pegasus`
command line, for any `threads`. Bad arguments raise ValueError naming the argument and what was expected.
Options, summaries and parameters are dataclass-like: `_fields` lists the C++ field names, and repr, == and
copy.copy use them.
"""
from ._pegasus import *  # noqa: F401,F403
from ._pegasus import (BicycleProblem, BoxPolicy, FiniteMdp, FunctionObjective, Objective,  # noqa: F401
                       OptimizerOptions, OptimizerSummary, Parameter, ParameterSpec, ScenarioSet,
                       VectorizedProblem, solve)
from . import _pegasus

# The pure-Python parts load on first use (PEP 562), so that `import pegasus` does not import numpy: the extension
# itself imports numpy only when it first exchanges an array.
_LAZY = {"finite_mdp": "mdp", "add_shaping": "mdp", "audit_shaping": "mdp", "gym": None,
         "TrainingPlan": "training", "TrainingStage": "training", "train": "training", "training": None}


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


def _fields_repr(self):
    return f"{type(self).__name__}({', '.join(f'{n}={getattr(self, n)!r}' for n in type(self)._fields)})"


def _fields_eq(self, other):
    if type(other) is not type(self):
        return NotImplemented
    for n in type(self)._fields:
        a, b = getattr(self, n), getattr(other, n)
        if hasattr(a, "shape") or hasattr(b, "shape"):  # numpy arrays: every entry, NaN equal to NaN
            import numpy
            if not numpy.array_equal(a, b, equal_nan=True):
                return False
        elif a != b and not (a != a and b != b):
            return False
    return True


for _cls in vars(_pegasus).values():
    if isinstance(_cls, type) and "_fields" in vars(_cls):
        if "__repr__" not in vars(_cls):
            _cls.__repr__ = _fields_repr
        _cls.__eq__ = _fields_eq
        _cls.__hash__ = None
del _cls

__version__ = "0.1.0"
