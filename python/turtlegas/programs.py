# SPDX-License-Identifier: MIT
"""Turtle programs written in Python (docs/python.md, "Python programs").

A program is a generator function `program(t, params)`. It yields its commands and gets each
command's result back as the value of the yield, so that it reads like a C++ controller:

    def wall_follower(t, p):
        while not (yield t.forward(1000)).touched:
            yield t.right(90 * t.uniform())
        ...

    world = turtlegas.World.load("worlds/wall_follower.json", programs={"righty": wall_follower})

Each program runs as its turtle's own program in the world server, on the turtle's coroutine,
where a C++ controller would run: at the turtle's turn the runtime resumes the generator, which
runs to its next yield; the command it yields goes through the same Turtle API as a C++
program's, and its result comes back when the command ends. One interpreter, on the thread that
calls World.run; no thread per turtle. The same program in C++ and in Python makes the same run.

Sub-programs are generators too, called with `yield from`:

    def back_off_and_turn(t, bearing):
        yield t.back(5)
        yield t.right(bearing + 180)

    moved = yield t.forward(100)
    if moved.touched:
        yield from back_off_and_turn(t, moved.touch.bearing)
"""

import collections


class Touch(collections.namedtuple("Touch", "sensors bearing what kind t")):
    """One touch: the names of the sensors that fired, the bearing of the contact (degrees
    clockwise from the heading, [0, 360)), the id of what was touched, its kind ("wall",
    "wall-end", "turtle" or "ball") and the time of contact (s)."""

    __slots__ = ()

    def fired(self, sensor):
        return sensor in self.sensors

    front = property(lambda self: "front" in self.sensors)
    right = property(lambda self: "right" in self.sensors)
    back = property(lambda self: "back" in self.sensors)
    left = property(lambda self: "left" in self.sensors)


class Reading(collections.namedtuple("Reading", "distance bearing what kind colour", defaults=("",))):
    """One ray of a range sensor: the distance to what it met (inf when nothing is within range),
    the ray's bearing (degrees clockwise from the heading), the id and kind of what it hit ("" when
    nothing); for a camera's pixel the colour ("#rrggbb") of what it hit, or the camera's background
    ("" for a range sensor that is no camera)."""

    __slots__ = ()
    hit = property(lambda self: self.kind != "")


class Message(collections.namedtuple("Message", "data t")):
    """A message from the world (the tag referee's): data, a dict with at least "kind", and t, when
    it was sent (s)."""

    __slots__ = ()
    kind = property(lambda self: self.data.get("kind", "") if isinstance(self.data, dict) else "")


class Result(collections.namedtuple("Result", "done touch")):
    """What a command did: done (units driven, degrees turned or seconds waited, >= 0) and touch,
    the Touch that cut it short, or None."""

    __slots__ = ()
    touched = property(lambda self: self.touch is not None)


class Command:
    """A command, made by a Turtle method, for the program to yield."""

    __slots__ = ("kind", "amount", "pen", "sensor", "first", "steer")

    def __init__(self, kind, amount=0.0, pen="line", sensor="", first=False, steer=()):
        self.kind = kind
        self.amount = float(amount)
        self.pen = pen
        self.sensor = sensor
        self.first = first  # range(): the first ray alone
        self.steer = tuple(float(x) for x in steer)  # arc, drive, wheels: their numbers

    def __repr__(self):
        if self.kind in ("sense", "camera"):
            return "Command(%s %r)" % (self.kind, self.sensor)
        if self.steer:
            return "Command(%s %s)" % (self.kind, ", ".join(repr(x) for x in self.steer))
        return "Command(%s %r)" % (self.kind, self.amount)


class Turtle:
    """The handle a Python program drives its turtle with: the C++ Turtle's methods (turtle.hpp).
    Motion, pen and sensing methods make commands to yield; the rest read the turtle now. Angles
    in degrees (Logo: heading 0 is +y, right turns clockwise), distances in world units, times in
    seconds. Valid while its program runs."""

    def __init__(self, handle):
        self._handle = handle
        self._on_touch = None
        self._on_message = None

    # Commands: yield them. The yield's value is a Result for forward, back, left, right, wait, arc,
    # drive and wheels;
    # a list of Readings for scan and camera; one Reading for range; None for yield_, pen_up and pen_down.
    def forward(self, distance):
        return Command("forward", distance)

    def back(self, distance):
        return Command("back", distance)

    def left(self, degrees):
        return Command("left", degrees)

    def right(self, degrees):
        return Command("right", degrees)

    def wait(self, seconds):
        return Command("wait", seconds)

    def arc(self, radius, degrees):
        """Drives along a circle of `radius` units through `degrees` of turn (positive right,
        clockwise; negative left), as Turtle::arc. The Result's done is the distance along it."""
        return Command("arc", steer=(radius, degrees))

    def drive(self, v, omega, seconds):
        """Drives for `seconds` at `v` units/s turning at `omega` degrees/s (positive clockwise)."""
        return Command("drive", steer=(v, omega, seconds))

    def wheels(self, left, right, seconds):
        """Differential drive: wheel speeds in units/s, the world file's "axle" apart."""
        return Command("wheels", steer=(left, right, seconds))

    def yield_(self):
        """Gives up the rest of this control step without a command."""
        return Command("yield")

    def pen_up(self):
        return Command("pen_up")

    def pen_down(self, mode="line"):
        if mode not in ("line", "wall"):
            raise ValueError('pen_down: mode must be "line" or "wall", got %r' % (mode,))
        return Command("pen_down", pen=mode)

    def scan(self, sensor):
        """Every ray of the range sensor, read now (no time passes): a list of Readings."""
        return Command("sense", sensor=sensor)

    def range(self, sensor):
        """The sensor's first ray, read now: a Reading."""
        return Command("sense", sensor=sensor, first=True)

    def camera(self, sensor):
        """Every pixel of the line camera, left to right, read now (no time passes): a list of
        Readings with their colours, as Turtle::camera."""
        return Command("camera", sensor=sensor)

    # Handlers, run by the runtime as the program resumes (touches first, then messages), before
    # the command they interrupted returns.
    def on_touch(self, handler):
        """handler(touch) for each touch; replaces any previous one (None: none)."""
        self._on_touch = handler

    def on_message(self, handler):
        """handler(message) for each message; replaces any previous one (None: none; messages that
        come with no handler are dropped)."""
        self._on_message = handler

    # Reading the turtle now: no command, no time.
    def uniform(self):
        """The turtle's own random stream (the C++ Turtle::uniform's), in [0, 1)."""
        return self._handle.uniform()

    def touching(self):
        """The touches in contact now: a list of Touch."""
        return self._handle.touching()

    def log(self, message):
        """A line for the run's log, tagged with the turtle's id."""
        self._handle.log(str(message))

    id = property(lambda self: self._handle.id)
    heading = property(lambda self: self._handle.heading, doc="degrees, Logo convention, [0, 360)")
    odometer = property(lambda self: self._handle.odometer, doc="units driven in all")
    position = property(lambda self: self._handle.position, doc='(x, y) where the world grants it ("gps"), else None')
    it = property(lambda self: self._handle.it, doc="whether the turtle is it in the world's tag game")
    time = property(lambda self: self._handle.time, doc="simulated time, seconds")
    radius = property(lambda self: self._handle.radius)
    speed = property(lambda self: self._handle.speed, doc="units per second")
    turn_rate = property(lambda self: self._handle.turn_rate, doc="degrees per second")
    axle = property(lambda self: self._handle.axle, doc='units between the wheels of wheels() ("axle"; twice the radius)')
    dt = property(lambda self: self._handle.dt, doc="the world's control step, seconds")
    pen_is_down = property(lambda self: self._handle.pen_is_down)
    pen_mode = property(lambda self: self._handle.pen_mode)
    game_rules = property(lambda self: self._handle.game_rules, doc="the world's game rules, {} without a game")
