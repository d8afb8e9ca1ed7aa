// SPDX-License-Identifier: MIT
// The table of compiled engine variants: one row per combination of the physics a scene can ask
// for, chosen here once per scene so that nothing is decided per collision.
//
// sim/CMakeLists.txt reads the rows of TURTLEGAS_ENGINE_VARIANTS below and compiles each in a
// translation unit of its own (engine_variants/*.cpp in the build tree: an explicit
// instantiation of make_variant), so the sixteen build in parallel. A row that is not listed is
// not compiled; a scene that would need it is a bug here, reported as such.
#include <stdexcept>
#include <string>

#include "engine_base.hpp"
#include "flights.hpp"
#include "variant_seam.hpp"

// flight, balls, mode, extras; within a mode the flights in order of cost (the factory takes the
// first row that serves the scene). Step mode flies straight and kicks between steps, so its rows
// all use FreeFlight (the engine refuses anything else).
#define TURTLEGAS_ENGINE_VARIANTS(ROW)         \
  ROW(FreeFlight, balls_meet, exact, plain)    \
  ROW(FreeFlight, balls_meet, exact, extras)   \
  ROW(FreeFlight, balls_pass, exact, plain)    \
  ROW(FreeFlight, balls_pass, exact, extras)   \
  ROW(GravityFlight, balls_meet, exact, plain) \
  ROW(GravityFlight, balls_meet, exact, extras) \
  ROW(GravityFlight, balls_pass, exact, plain) \
  ROW(GravityFlight, balls_pass, exact, extras) \
  ROW(ChargedFlight, balls_meet, exact, plain) \
  ROW(ChargedFlight, balls_meet, exact, extras) \
  ROW(ChargedFlight, balls_pass, exact, plain) \
  ROW(ChargedFlight, balls_pass, exact, extras) \
  ROW(FreeFlight, balls_meet, step, plain)     \
  ROW(FreeFlight, balls_meet, step, extras)    \
  ROW(FreeFlight, balls_pass, step, plain)     \
  ROW(FreeFlight, balls_pass, step, extras)

namespace turtlegas::sim::detail {

#define TURTLEGAS_DECLARE_ROW(flight, balls, mode, extras)                                                  \
  extern template std::unique_ptr<EngineBase> make_variant<flight, variant::balls, variant::mode, variant::extras>( \
      const WorldDef&, std::vector<BallDef>*);
TURTLEGAS_ENGINE_VARIANTS(TURTLEGAS_DECLARE_ROW)
#undef TURTLEGAS_DECLARE_ROW

namespace {

/// Whether the scene has turtles, collision layers or moving (or blinking) walls.
bool needs_extras(const WorldDef& def) {
  const Layers plain{};
  bool layered = false;
  for (const auto& b : def.balls) layered = layered || !(b.layers == plain);
  for (const auto& t : def.turtles) layered = layered || !(t.layers == plain);
  for (const auto& w : def.walls) layered = layered || !(w.layers == plain) || !w.keys.empty() || !w.visibility.empty();
  return !def.turtles.empty() || layered;
}

/// Whether a row's flight serves the scene: in exact mode when the flight fits it (the
/// rows are in order of cost, so the first that fits is the cheapest); in step mode always (it
/// flies straight and kicks between steps).
template <Flight F>
bool flight_serves(const WorldDef& def, bool step) {
  return step || F::fits(def);
}

std::unique_ptr<EngineBase> make(const WorldDef& def, Mode mode, std::vector<BallDef>* release) {
  const bool ball_ball = def.effects.ball_ball;
  const bool step = mode == Mode::step;
  const bool extras = needs_extras(def);
#define TURTLEGAS_TRY_ROW(flight, balls, mode_, extras_)                                                \
  if (step == variant::mode_ && ball_ball == variant::balls && extras == variant::extras_ &&            \
      flight_serves<flight>(def, step))                                                                 \
    return make_variant<flight, variant::balls, variant::mode_, variant::extras_>(def, release);
  TURTLEGAS_ENGINE_VARIANTS(TURTLEGAS_TRY_ROW)
#undef TURTLEGAS_TRY_ROW
  throw std::logic_error("no engine variant compiled for this scene; add its row to sim/src/engine/factory.cpp");
}

}  // namespace

std::unique_ptr<EngineBase> make_engine(const WorldDef& def, Mode mode) { return make(def, mode, nullptr); }

std::unique_ptr<EngineBase> make_engine(WorldDef&& def, Mode mode) { return make(def, mode, &def.balls); }

}  // namespace turtlegas::sim::detail
