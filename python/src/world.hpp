// SPDX-License-Identifier: MIT
// turtlegas.World: one world file's run, in process (docs/python.md). A thin layer over the CLI's
// libraries: the loader (world_files), the bare engine (sim::World) for scenes without turtles, as
// `turtlegas run` runs them, the world server (turtle::WorldServer) for scenes with turtles, and
// the writers and the observer of formats/. No physics here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "programs.hpp"
#include "turtlegas/sim/world.hpp"
#include "turtlegas/turtle/log_event.hpp"
#include "turtlegas/turtle/registry.hpp"
#include "turtlegas/turtle/world_server.hpp"
#include "turtlegas/world/scene.hpp"

namespace turtlegas::python {

namespace py = pybind11;

class World {
 public:
  /// Loads a world file (a path) or a world given as a dict (the same keys). `mode` is "exact" or
  /// "step"; `dt` overrides the file's; `programs` maps turtle ids to Python programs (generator
  /// functions, programs.py); `events` false keeps no event log. Throws world::WorldFileError
  /// (turtlegas.WorldError) for a world the loader refuses, std::invalid_argument for bad
  /// arguments.
  static std::unique_ptr<World> load(const py::object& source, const std::string& mode, std::optional<double> dt,
                                     const py::dict& programs, bool events, bool unwrap);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  /// Runs to time `until` (seconds, >= time()); the GIL is released while the engine runs.
  void run(double until);
  double time() const;
  std::string mode() const;
  double dt() const { return scene_.def.dt; }
  bool has_turtles() const { return server_ != nullptr; }

  // State, read now. Balls by index (the world file's order, spawned balls after).
  py::array_t<double> positions() const;
  py::array_t<double> velocities() const;
  py::array_t<bool> alive() const;
  /// Per ball, read-only arrays the module keeps: no copy per call (new ones after a spawn).
  py::array radii();
  py::array masses();
  py::array charges();
  py::list ball_ids() const;
  /// Positions in a periodic arena followed across its seams (None elsewhere, or unwrap=False).
  py::object unwrapped();
  py::array_t<double> turtle_positions() const;
  py::array_t<double> headings() const;  ///< degrees, Logo convention, [0, 360)
  py::list turtle_ids() const;
  double energy() const;
  py::dict stats() const;

  /// The events since the last call of any of the three, consumed: as a numpy structured array,
  /// as a list of turtlegas.Event named tuples, or as the event log's lines (JSON Lines, as
  /// `turtlegas run --events` writes them).
  py::array events_array();
  py::list events_list();
  std::string event_lines();

  /// Runs to `until` observing the gas as `turtlegas run --observe` does, and returns the same
  /// figures (format turtlegas-observables/1) as a dict.
  py::object observe(double until, double from, double window, int samples, const std::string& axis, int bins,
                     int speed_bins);

  // Changes while it runs (docs/physics.md, "Bodies added, removed and moved at run time"): at once
  // in a world without turtles (the engine's own operations), at the next control boundary in a
  // world with turtles (the world server's, as the protocol's world changes).
  void spawn_ball(const std::string& id, std::pair<double, double> pos, std::pair<double, double> vel, double radius,
                  double mass, double charge);
  /// A turtle standing still, running `controller` (registered) or `program` (a Python program).
  void spawn_turtle(const std::string& id, std::pair<double, double> pos, double heading,
                    double radius, double speed, double turn_rate, const std::string& controller,
                    const py::object& params, const py::object& program);
  void remove(const std::string& id);
  /// A ball gets `vel` (None: the one it has), a turtle `heading` (degrees; None: the one it has).
  void teleport(const std::string& id, std::pair<double, double> pos, const py::object& vel, const py::object& heading);
  void add_wall(const std::string& id, std::pair<double, double> from, std::pair<double, double> to);

 private:
  World() = default;
  void take_events();
  void require_runnable() const;
  void check_new_id(const std::string& id) const;
  /// The live ball with that id.
  std::optional<std::size_t> live_ball(const std::string& id) const;
  /// The engine's refusal, with the obstacle named by its id (as world_changes.cpp words it).
  [[noreturn]] void refuse(const std::string& who, const sim::PlacementError& e) const;
  /// A change made at once (no turtles): its event, after the engine's events so far.
  void log_change(const char* kind, const std::string& id, const std::string& what);
  /// Runs the engine (or the world server) to `until`.
  void advance(double until);
  /// Runs to `until` by `advance`, in runs short enough to follow the unwrapped positions.
  void run_in_reads(double until, const std::function<void(double)>& advance);
  void refresh_ball_arrays();
  void note_new_balls();
  sim::World& bare() { return *bare_; }
  const sim::World& engine() const { return server_ ? server_->world() : *bare_; }
  const sim::WorldDef& scene_def() const { return server_ ? server_->scene() : scene_.def; }

  world::Scene scene_;
  sim::Mode mode_ = sim::Mode::exact;
  turtle::Registry registry_;
  std::optional<sim::World> bare_;
  std::unique_ptr<turtle::WorldServer> server_;
  std::shared_ptr<ChangeQueue> changes_;
  std::shared_ptr<Programs> programs_;
  bool log_events_ = true;
  std::vector<sim::Event> engine_events_;       // the bare engine's log, between takes
  std::vector<turtle::LogEvent> server_events_;  // the world server's log, between takes
  std::vector<turtle::LogEvent> pending_;        // events not yet taken, ids resolved
  bool running_ = false;
  std::string broken_;  // why the world cannot run on (an exception inside the engine's run)
  // Unwrapped positions (periodic arenas): followed by the nearest image at least every time a
  // ball can cross a quarter of the arena (run_in_reads).
  bool unwrap_ = false;
  std::vector<double> unwrapped_, last_wrapped_;
  std::vector<double> images_;  // whole periods crossed per coordinate (integers)
  std::vector<std::size_t> restart_;  // teleported balls: their unwrapped track starts again
  double min_mass_ = 0.0;
  // The ball arrays radii(), masses(), charges() hand out; rebuilt when balls are added.
  std::size_t arrays_for_ = static_cast<std::size_t>(-1);
  py::array radii_, masses_, charges_;
};

/// Adds World, WorldError, ProgramError and the event record type to the module.
void bind_world(py::module_& m);

}  // namespace turtlegas::python
