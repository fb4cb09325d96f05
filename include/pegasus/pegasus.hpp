#pragma once
// Everything a program needs to tune a policy on its own model with pegasus::core (examples/own-model):
// the model concept, policies and their parameters, scenario sets, the PEGASUS and Monte Carlo evaluators,
// every optimizer and the training loop, with the errors they throw. Components beyond the core have their
// own headers: pegasus/parallel/open_mpi.hpp (pegasus::mpi), pegasus/mujoco/ (pegasus::mujoco), and
// pegasus/runs/ and each domain's experiments in pegasus/DOMAIN/runs/ (pegasus::runs).
#include "pegasus/core/environment_error.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/evaluators/monte_carlo.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/models/action_space.hpp"
#include "pegasus/models/model.hpp"
#include "pegasus/optimizers/optimizer.hpp"
#include "pegasus/optimizers/training.hpp"
#include "pegasus/parallel/execution_context.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/policies/parameter_spec.hpp"
#include "pegasus/policies/policies.hpp"
#include "pegasus/scenarios/scenario_set.hpp"
#include "pegasus/version.hpp"
