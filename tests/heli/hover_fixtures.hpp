#pragma once
// The small identified models and the X-Cell's hover policy file that the hover tests share (tests/heli).
#include <memory>

#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::heli::test_fixtures {

// A model identified from a short pilot flight (a few tenths of a second); `reversed` negates a1 and a4 in
// the logs first, as an aircraft whose longitudinal cyclic and tail act with the opposite signs; `local`
// false fits the global linear class.
inline std::shared_ptr<const sysid::IdentifiedModel> identify_pilot_flight(bool reversed, bool local = true) {
  const Aircraft heli;
  PilotOptions o;
  o.hover_seconds = 4;
  auto log = fly_pilot(heli, o, 60, 3).log;
  if (reversed)
    for (auto& a : log.controls) a[0] = -a[0], a[3] = -a[3];
  sysid::IdentifyOptions io;
  io.cv_points = 40;
  io.scale_grid = {2, 4};
  io.coordinate_passes = 0;
  io.local = local;
  ThreadPool pool(2);
  return std::make_shared<const sysid::IdentifiedModel>(sysid::identify(log, io, pool));
}

// Made once each.
inline std::shared_ptr<const sysid::IdentifiedModel> small_model() {
  static const auto model = identify_pilot_flight(false);
  return model;
}

// The X-Cell's hover policy at its calm-air trim, with or without the integral term.
inline PolicyFile xcell_hover_file(const Aircraft& aircraft, double integral_seconds) {
  const HoverPoint trim = aircraft.hover_point();
  const HoverPolicy pi(HoverPolicyInit{.trim = trim.controls,
                                       .trim_roll = trim.roll,
                                       .trim_pitch = trim.pitch,
                                       .integral_seconds = integral_seconds});
  const ErrorIntegrator integrator{.dt = integral_seconds > 0 ? 0.02 : 0.0};
  return hover_policy_file(pi, pi.parameters().initial(), {0, 0, -10, 0}, trim.controls, integrator);
}

}  // namespace pegasus::heli::test_fixtures
