#pragma once
// The pilot logs and the small bandwidth search the identification tests share (tests/sysid).
#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::sysid::test {

struct Logs {
  FlightLog train, test;
};
// The scripted pilot over the X-Cell: 200 s to train (seed 41), 80 s to test (seed 42); built once.
inline const Logs& logs() {
  static const Logs l = [] {
    const heli::Aircraft heli;
    heli::PilotOptions o;
    o.hover_seconds = 4;
    return Logs{heli::fly_pilot(heli, o, 200, 41).log, heli::fly_pilot(heli, o, 80, 42).log};
  }();
  return l;
}

inline IdentifyOptions small_search() {
  IdentifyOptions o;
  o.cv_points = 60;
  o.scale_grid = {1, 2, 4};
  o.coordinate_passes = 1;
  return o;
}

}  // namespace pegasus::sysid::test
