// SPDX-License-Identifier: MIT
// turtlegas._VecWorld: learn::VecWorld for Python, its buffers numpy arrays, the GIL released while
// the copies step. turtlegas/vec.py wraps it (rewards, the Gymnasium / PettingZoo shapes).
#include <cstdint>
#include <stdexcept>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "turtlegas/controllers/registry.hpp"
#include "turtlegas/learn/vec_world.hpp"
#include "turtlegas/world/world_file.hpp"
#include "vec_world_py.hpp"

namespace py = pybind11;

namespace turtlegas::python {
namespace {

using learn::VecWorld;
using Floats = py::array_t<float, py::array::c_style | py::array::forcecast>;
using Ints = py::array_t<std::int32_t, py::array::c_style | py::array::forcecast>;

learn::ActionKind action_kind(const std::string& s) {
  if (s == "velocity") return learn::ActionKind::velocity;
  if (s == "wheels") return learn::ActionKind::wheels;
  if (s == "logo") return learn::ActionKind::logo;
  throw std::invalid_argument("actions must be \"velocity\", \"wheels\" or \"logo\", not \"" + s + "\"");
}

sim::Mode mode_of(const std::string& s) {
  if (s == "exact") return sim::Mode::exact;
  if (s == "step") return sim::Mode::step;
  throw std::invalid_argument("mode must be \"exact\" or \"step\", not \"" + s + "\"");
}

py::array_t<float> obs_array(const VecWorld& v) {
  return py::array_t<float>({v.size(), v.turtle_count(), v.obs_size()});
}

std::span<float> span_of(py::array_t<float>& a) { return {a.mutable_data(), static_cast<std::size_t>(a.size())}; }

}  // namespace

void bind_vec_world(py::module_& m) {
  py::class_<VecWorld>(m, "_VecWorld", "learn::VecWorld: n copies of a world file's scene (use turtlegas.VecWorld)")
      .def(py::init([](const std::string& text, const std::string& name, std::size_t n, std::size_t threads, const std::string& actions,
                       bool random_start, std::uint64_t max_steps, const std::string& mode) {
             static const turtle::Registry registry = controllers::builtin_registry();
             learn::VecWorldOptions o;
             o.threads = threads;
             o.actions = action_kind(actions);
             o.random_start = random_start;
             o.max_steps = max_steps;
             o.mode = mode_of(mode);
             return new VecWorld(world::parse_scene(text, name, registry), n, o);
           }),
           py::arg("text"), py::arg("name"), py::arg("n"), py::arg("threads") = 0, py::arg("actions") = "velocity",
           py::arg("random_start") = true, py::arg("max_steps") = 0, py::arg("mode") = "exact")
      .def_property_readonly("size", &VecWorld::size)
      .def_property_readonly("turtle_count", &VecWorld::turtle_count)
      .def_property_readonly("thread_count", &VecWorld::thread_count)
      .def_property_readonly("obs_size", &VecWorld::obs_size)
      .def_property_readonly("action_size", &VecWorld::action_size)
      .def_property_readonly("turtle_ids", &VecWorld::turtle_ids)
      .def_property_readonly("dt", &VecWorld::dt)
      .def_property_readonly("turtle_speeds", &VecWorld::turtle_speeds)
      .def_property_readonly("layout", [](const VecWorld& v) {
        const learn::ObsLayout& l = v.layout();
        py::dict d;
        d["touch"] = py::slice(static_cast<py::ssize_t>(l.touch), static_cast<py::ssize_t>(l.touch + l.touch_count), 1);
        d["range"] = py::slice(static_cast<py::ssize_t>(l.range), static_cast<py::ssize_t>(l.range + l.range_count), 1);
        d["odometry"] = py::slice(static_cast<py::ssize_t>(l.odometry), static_cast<py::ssize_t>(l.odometry + 2), 1);
        d["heading"] = py::slice(static_cast<py::ssize_t>(l.heading), static_cast<py::ssize_t>(l.heading + 2), 1);
        d["gps"] = py::slice(static_cast<py::ssize_t>(l.gps), static_cast<py::ssize_t>(l.gps + 2 * l.gps_count), 1);
        return d;
      })
      .def("reset", [](VecWorld& v, std::uint64_t seed) {
        py::array_t<float> obs = obs_array(v);
        std::span<float> s = span_of(obs);
        {
          py::gil_scoped_release release;
          v.reset(seed, s);
        }
        return obs;
      }, py::arg("seed"))
      .def("reset_one", [](VecWorld& v, std::size_t i, std::uint64_t seed, py::array_t<float, py::array::c_style> obs) {
        if (obs.ndim() != 3 || static_cast<std::size_t>(obs.size()) != v.size() * v.turtle_count() * v.obs_size())
          throw std::invalid_argument("reset_one: obs must be the (n, turtles, obs_size) float32 array step returned");
        v.reset_one(i, seed, {obs.mutable_data(), static_cast<std::size_t>(obs.size())});
      }, py::arg("i"), py::arg("seed"), py::arg("obs"))
      .def("step", [](VecWorld& v, py::array actions) {
        py::array_t<float> obs = obs_array(v);
        py::array_t<bool> term(v.size()), trunc(v.size());
        std::span<float> so = span_of(obs);
        static_assert(sizeof(bool) == sizeof(std::uint8_t));
        std::span<std::uint8_t> st{reinterpret_cast<std::uint8_t*>(term.mutable_data()), v.size()};
        std::span<std::uint8_t> su{reinterpret_cast<std::uint8_t*>(trunc.mutable_data()), v.size()};
        const std::size_t need = v.size() * v.turtle_count() * v.action_size();
        if (static_cast<std::size_t>(actions.size()) != need)
          throw std::invalid_argument("step: " + std::to_string(actions.size()) + " action values; it needs (" + std::to_string(v.size()) + ", " +
                                      std::to_string(v.turtle_count()) + (v.action_size() == 2 ? ", 2)" : ")") + " = " + std::to_string(need));
        if (v.options().actions == learn::ActionKind::logo) {
          Ints a = Ints::ensure(actions);
          if (!a) throw py::error_already_set();
          std::span<const std::int32_t> sa{a.data(), need};
          py::gil_scoped_release release;
          v.step(sa, so, st, su);
        } else {
          Floats a = Floats::ensure(actions);
          if (!a) throw py::error_already_set();
          std::span<const float> sa{a.data(), need};
          py::gil_scoped_release release;
          v.step(sa, so, st, su);
        }
        return py::make_tuple(obs, term, trunc);
      }, py::arg("actions"))
      .def("sample_actions", [](VecWorld& v) -> py::array {
        if (v.options().actions == learn::ActionKind::logo) {
          py::array_t<std::int32_t> a({v.size(), v.turtle_count()});
          v.sample_actions(std::span<std::int32_t>{a.mutable_data(), static_cast<std::size_t>(a.size())});
          return a;
        }
        py::array_t<float> a({v.size(), v.turtle_count(), std::size_t{2}});
        v.sample_actions(span_of(a));
        return a;
      })
      .def("positions", [](const VecWorld& v) {
        // Ground truth for rewards (whether or not the turtles have gps): (n, turtles, 2), and NaN
        // for a turtle gone.
        py::array_t<double> a({v.size(), v.turtle_count(), std::size_t{2}});
        double* p = a.mutable_data();
        for (std::size_t i = 0; i < v.size(); ++i)
          for (std::size_t k = 0; k < v.turtle_count(); ++k, p += 2) {
            const sim::World& w = v.world(i);
            if (w.turtle_alive(k)) {
              const sim::Vec2 x = w.turtle(k).pos;
              p[0] = x.x, p[1] = x.y;
            } else {
              p[0] = p[1] = std::numeric_limits<double>::quiet_NaN();
            }
          }
        return a;
      })
      .def("headings", [](const VecWorld& v) {
        // Degrees, Logo convention (0 is +y, clockwise), as the world file writes them: (n, turtles).
        py::array_t<double> a({v.size(), v.turtle_count()});
        double* p = a.mutable_data();
        for (std::size_t i = 0; i < v.size(); ++i)
          for (std::size_t k = 0; k < v.turtle_count(); ++k) *p++ = v.world(i).turtle(k).heading * 180.0 / M_PI;
        return a;
      })
      .def("contacts", [](const VecWorld& v) {
        py::array_t<std::uint64_t> a(v.size());
        for (std::size_t i = 0; i < v.size(); ++i) a.mutable_data()[i] = v.last_contacts(i);
        return a;
      })
      .def("steps", [](const VecWorld& v) {
        py::array_t<std::uint64_t> a(v.size());
        for (std::size_t i = 0; i < v.size(); ++i) a.mutable_data()[i] = v.steps(i);
        return a;
      })
      .def("times", [](const VecWorld& v) {
        py::array_t<double> a(v.size());
        for (std::size_t i = 0; i < v.size(); ++i) a.mutable_data()[i] = v.world(i).time();
        return a;
      });
}

}  // namespace turtlegas::python
