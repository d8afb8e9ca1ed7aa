// SPDX-License-Identifier: MIT
#include "programs.hpp"

#include <exception>
#include <stdexcept>
#include <utility>
#include <vector>

#include <pybind11/stl.h>

#include "turtlegas/turtle/turtle.hpp"

namespace turtlegas::python {

void ChangeQueue::at_boundary(turtle::WorldServer& s, std::uint64_t) {
  std::vector<Change> now = std::move(changes);
  changes.clear();
  for (const Change& c : now) {
    try {
      c(s);
    } catch (const std::exception& e) {  // refused, nothing changed: World.run raises it after the run
      refused.emplace_back(e.what());
    }
  }
}

namespace {

/// What a program's Python Turtle reads through: the program's turtle::Turtle while the program
/// runs, nothing after (a Turtle kept past its program's end raises).
struct TurtleHandle {
  turtle::Turtle* t = nullptr;
  turtle::Turtle& get() const {
    if (!t) throw std::logic_error("this Turtle's program has ended");
    return *t;
  }
};

py::object json_to_py(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

py::object touch_object(const py::object& progs, const turtle::Touch& t) {
  py::list sensors;
  if (t.sensor_names)
    for (std::size_t s = 0; s < t.sensor_names->size(); ++s)
      if (t.fired(s)) sensors.append((*t.sensor_names)[s]);
  return progs.attr("Touch")(py::tuple(sensors), t.bearing, t.what, t.kind, t.t);
}

py::object reading_object(const py::object& progs, const turtle::Reading& r) {
  return progs.attr("Reading")(r.distance, r.bearing, r.what, r.kind, r.colour);
}

/// The Python objects of one running program, let go with the GIL held however the program ends
/// (it returns, raises, its turtle is gone, or the world unwinds it).
struct Held {
  py::object progs, handle, turtle, generator, answer;
  ~Held() {
    py::gil_scoped_acquire gil;
    if (handle) handle.cast<TurtleHandle&>().t = nullptr;
    progs = handle = turtle = generator = answer = py::object();
  }
};

/// A command a program yielded, read with the GIL held and run without it.
struct Command {
  std::string kind;
  double amount = 0.0;
  turtle::PenMode pen = turtle::PenMode::line;
  std::string sensor;
  bool first = false;
  std::vector<double> steer;  // arc, drive, wheels
};

/// The program's exception, kept for World.run (the first one), and the fault the runtime logs.
[[noreturn]] void program_failed(Programs& programs, py::error_already_set& e) {
  const std::string what = e.what();
  if (!programs.error) programs.error.emplace(std::move(e));
  throw std::runtime_error("its Python program raised " + what);
}

void run(Programs& programs, turtle::Turtle& t, const turtle::Params& p) {
  Held held;
  {
    py::gil_scoped_acquire gil;
    held.progs = py::module_::import("turtlegas.programs");
    try {
      const auto found = programs.functions.find(t.id());
      if (found == programs.functions.end())
        throw py::value_error("turtle '" + t.id() + "' runs the controller \"python\" but World.load was given no "
                              "program for it (programs={\"" + t.id() + "\": ...})");
      held.handle = py::cast(TurtleHandle{&t});
      held.turtle = held.progs.attr("Turtle")(held.handle);
      held.generator = found->second(held.turtle, json_to_py(p.json()));
      if (!py::hasattr(held.generator, "send"))
        throw py::type_error("turtle '" + t.id() + "': its program must be a generator function (it yields its "
                             "commands: `yield t.forward(10)`), but it returned " +
                             std::string(py::repr(held.generator)));
    } catch (py::error_already_set& e) {
      program_failed(programs, e);
    } catch (const py::builtin_exception& e) {
      e.set_error();
      py::error_already_set err;
      program_failed(programs, err);
    }
  }
  // The program's handlers, called by the runtime as it resumes the program (touches, then
  // messages, before the command they interrupted returns).
  auto call_handler = [&programs, &held, &t](const char* name, auto make) {
    py::gil_scoped_acquire gil;
    try {
      py::object handler = held.turtle.attr(name);
      if (!handler.is_none()) handler(make());
    } catch (py::error_already_set& e) {
      program_failed(programs, e);
    }
  };
  t.on_touch([&](const turtle::Touch& touch) {
    call_handler("_on_touch", [&] { return touch_object(held.progs, touch); });
  });
  t.on_message([&](const turtle::Message& m) {
    call_handler("_on_message", [&] { return held.progs.attr("Message")(json_to_py(m.data), m.t); });
  });

  std::vector<turtle::Reading> readings;
  bool started = false;
  for (;;) {
    Command c;
    {
      py::gil_scoped_acquire gil;
      try {
        py::object yielded;
        try {
          yielded = started ? held.generator.attr("send")(held.answer) : held.generator.attr("__next__")();
        } catch (py::error_already_set& e) {
          if (e.matches(PyExc_StopIteration)) return;  // the program returned: its turtle is parked
          throw;
        }
        started = true;
        if (!py::isinstance(yielded, held.progs.attr("Command")))
          throw py::type_error("turtle '" + t.id() + "': a program yields commands (t.forward(10), t.scan(\"ir\"), "
                               "...), not " + std::string(py::repr(yielded)));
        c.kind = yielded.attr("kind").cast<std::string>();
        c.amount = yielded.attr("amount").cast<double>();
        c.pen = yielded.attr("pen").cast<std::string>() == "wall" ? turtle::PenMode::wall : turtle::PenMode::line;
        c.sensor = yielded.attr("sensor").cast<std::string>();
        c.first = yielded.attr("first").cast<bool>();
        c.steer = yielded.attr("steer").cast<std::vector<double>>();
      } catch (py::error_already_set& e) {
        program_failed(programs, e);
      } catch (const py::builtin_exception& e) {
        e.set_error();
        py::error_already_set err;
        program_failed(programs, err);
      }
    }
    // The command, through the Turtle API as a C++ program calls it (its coroutine suspends here).
    std::optional<turtle::Result> result;
    readings.clear();
    if (c.kind == "forward") result = t.forward(c.amount);
    else if (c.kind == "back") result = t.back(c.amount);
    else if (c.kind == "left") result = t.left(c.amount);
    else if (c.kind == "right") result = t.right(c.amount);
    else if (c.kind == "wait") result = t.wait(c.amount);
    else if (c.kind == "arc" && c.steer.size() == 2) result = t.arc(c.steer[0], c.steer[1]);
    else if (c.kind == "drive" && c.steer.size() == 3) result = t.drive(c.steer[0], c.steer[1], c.steer[2]);
    else if (c.kind == "wheels" && c.steer.size() == 3) result = t.wheels(c.steer[0], c.steer[1], c.steer[2]);
    else if (c.kind == "yield") t.yield();
    else if (c.kind == "pen_up") t.pen_up();
    else if (c.kind == "pen_down") t.pen_down(c.pen);
    else if (c.kind == "sense") t.scan(c.sensor, readings);
    else if (c.kind == "camera") t.camera(c.sensor, readings);
    else throw std::logic_error("programs.py made an unknown command '" + c.kind + "'");
    py::gil_scoped_acquire gil;
    if (result) {
      held.answer = held.progs.attr("Result")(result->done(),
                                              result->touched() ? touch_object(held.progs, result->touch()) : py::none());
    } else if (c.kind == "sense" || c.kind == "camera") {
      py::list rays;
      for (const turtle::Reading& r : readings) rays.append(reading_object(held.progs, r));
      held.answer = c.first ? (rays.empty() ? py::none() : py::object(rays[0])) : py::object(rays);
    } else {
      held.answer = py::none();
    }
  }
}

}  // namespace

turtle::Controller python_program(std::shared_ptr<Programs> programs) {
  return [programs](turtle::Turtle& t, const turtle::Params& p) { run(*programs, t, p); };
}

void bind_programs(py::module_& m) {
  py::class_<TurtleHandle>(m, "_TurtleHandle", "What a Python program's Turtle reads (programs.py)")
      .def("uniform", [](const TurtleHandle& h) { return h.get().uniform(); })
      .def_property_readonly("heading", [](const TurtleHandle& h) { return h.get().heading(); })
      .def_property_readonly("odometer", [](const TurtleHandle& h) { return h.get().odometer(); })
      .def_property_readonly("position", [](const TurtleHandle& h) -> py::object {
        const std::optional<sim::Vec2> p = h.get().position();
        return p ? py::object(py::make_tuple(p->x, p->y)) : py::none();
      })
      .def_property_readonly("it", [](const TurtleHandle& h) { return h.get().it(); })
      .def_property_readonly("time", [](const TurtleHandle& h) { return h.get().time(); })
      .def_property_readonly("id", [](const TurtleHandle& h) { return h.get().id(); })
      .def_property_readonly("radius", [](const TurtleHandle& h) { return h.get().radius(); })
      .def_property_readonly("speed", [](const TurtleHandle& h) { return h.get().speed(); })
      .def_property_readonly("turn_rate", [](const TurtleHandle& h) { return h.get().turn_rate(); })
      .def_property_readonly("axle", [](const TurtleHandle& h) { return h.get().axle(); })
      .def_property_readonly("dt", [](const TurtleHandle& h) { return h.get().dt(); })
      .def_property_readonly("pen_is_down", [](const TurtleHandle& h) { return h.get().pen_is_down(); })
      .def_property_readonly("pen_mode", [](const TurtleHandle& h) {
        return h.get().pen_mode() == turtle::PenMode::wall ? "wall" : "line";
      })
      .def_property_readonly("game_rules", [](const TurtleHandle& h) { return json_to_py(h.get().game_rules()); })
      .def("touching", [](const TurtleHandle& h) {
        const py::object progs = py::module_::import("turtlegas.programs");
        py::list out;
        for (const turtle::Touch& t : h.get().touching()) out.append(touch_object(progs, t));
        return out;
      })
      .def("log", [](const TurtleHandle& h, const std::string& message) { h.get().log(message); });
}

}  // namespace turtlegas::python
