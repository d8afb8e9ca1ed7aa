# SPDX-License-Identifier: MIT
"""A client for `turtlegas serve` (docs/protocol.md), Python 3 standard library only.

(Just over 600 lines, in one file on purpose: it is the client a user copies next to a script,
with nothing to install; split, it would need a package.)

It reads like the C++ controller API:

    world = World.connect("127.0.0.1", 8081)          # TCP lines (or World.connect_ws(url))
    t = world.claim("t1")
    r = t.forward(100)
    if r.touched:
        t.right(90)

Each command blocks until its result comes back. Touches and messages that arrive before a
result are handed to the turtle's on_touch / on_message handlers (in the calling thread, just
before the command returns), as a C++ program's handlers see them. Several turtles can be driven
from one connection, each from its own thread (`World.run_turtles`), which a lockstep world needs
when one client drives two turtles.

Replies are read by the thread that waits for them: no reader thread stands between the socket
and a command's caller (a hand-off between threads costs tens of microseconds, more than the rest
of a round trip; docs/performance.md, "The world server"). When several threads wait, one reads
for all and passes the others' messages on. Frames and notices are read the same way, by
`world.frames.get()` and `world.notices.get()`; `World.connect(..., background=True)` starts a
thread that keeps reading when nobody waits (a viewer that does other work between frames).
"""

import base64
import collections
import json
import os
import queue
import select
import socket
import struct
import threading
import time

PROTOCOL = "turtlegas/1"


class ServerError(Exception):
    """An error reply: .code, .message, .field, .reply (the whole message)."""

    def __init__(self, reply):
        self.reply = reply
        self.code = reply.get("code")
        self.field = reply.get("field")
        super().__init__("%s: %s" % (self.code, reply.get("message")))


class Closed(Exception):
    """The server closed the connection (its world stopped: .bye is its last message, if any)."""

    def __init__(self, bye=None):
        self.bye = bye
        super().__init__("connection closed" + (" (%s)" % bye.get("reason") if bye else ""))


class Touch:
    def __init__(self, d):
        self.sensors = list(d.get("sensors", []))
        self.bits = d.get("bits", 0)
        self.bearing = d.get("bearing", 0.0)
        self.what = d.get("what", "")
        self.kind = d.get("kind", "")
        self.t = d.get("t", 0.0)

    def fired(self, name):
        return name in self.sensors

    front = property(lambda self: self.fired("front"))
    right = property(lambda self: self.fired("right"))
    back = property(lambda self: self.fired("back"))
    left = property(lambda self: self.fired("left"))

    def __repr__(self):
        return "Touch(%s %r %s bearing=%g t=%g)" % (self.kind, self.what, self.sensors, self.bearing, self.t)


class Result:
    """What a command did, as Result in turtle.hpp: done, touched, touch; and where and when."""

    def __init__(self, d):
        self.reply = d
        self.done = d.get("done", 0.0)
        self.touched = bool(d.get("touched"))
        self.touch = Touch(d["touch"]) if self.touched else None
        self.t = d.get("t")
        self.step = d.get("step")
        self.state = d.get("state", {})

    def __repr__(self):
        return "Result(done=%g, touched=%s, t=%g)" % (self.done, self.touched, self.t)


class Reading:
    """One ray of a range sensor, as Reading in turtle.hpp: distance (world units from the turtle's
    centre; math.inf when nothing is within range), bearing (degrees clockwise from the heading),
    what (an id) and kind ("wall", "wall-end", "ball", "turtle"; None when nothing is hit); a
    camera's pixel also has colour ("#rrggbb" of what it hit, or the camera's background; None for
    a range sensor that is no camera)."""

    def __init__(self, d):
        self.bearing = d["bearing"]
        self.distance = d["distance"] if d.get("distance") is not None else float("inf")
        self.what = d.get("what")
        self.kind = d.get("kind")
        self.colour = d.get("colour")

    @property
    def hit(self):
        return self.kind is not None

    def __repr__(self):
        if self.colour is not None:
            return "Reading(bearing=%g, distance=%g, what=%r, colour=%r)" % (
                self.bearing, self.distance, self.what, self.colour)
        return "Reading(bearing=%g, distance=%g, what=%r)" % (self.bearing, self.distance, self.what)


# ---- transports ---------------------------------------------------------------------------------

def _wait_readable(sock, deadline):
    """Blocks until `sock` has data; TimeoutError at `deadline` (time.monotonic(), None: never)."""
    if deadline is None:
        return
    left = max(0.0, deadline - time.monotonic())
    if not select.select([sock], [], [], left)[0]:
        raise TimeoutError


class _Lines:
    def __init__(self, host, port, timeout):
        self.sock = socket.create_connection((host, port), timeout=timeout)
        self.sock.settimeout(None)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.buf = bytearray()

    def send(self, text):
        self.sock.sendall(text.encode("utf-8") + b"\n")

    def receive(self, deadline=None):
        """The next line (str); None at the end; TimeoutError at `deadline` (nothing is lost)."""
        while True:
            i = self.buf.find(b"\n")
            if i >= 0:
                line = bytes(self.buf[:i])
                del self.buf[:i + 1]
                return line.decode("utf-8", "replace")
            _wait_readable(self.sock, deadline)
            try:
                chunk = self.sock.recv(262144)
            except OSError:
                return None
            if not chunk:
                return None
            self.buf += chunk

    def close(self):
        try:
            self.sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self.sock.close()


class _WebSocket:
    """A minimal RFC 6455 client: masked text frames out; text, binary, ping, close in."""

    def __init__(self, host, port, path, timeout):
        self.sock = socket.create_connection((host, port), timeout=timeout)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        key = base64.b64encode(os.urandom(16)).decode()
        self.sock.sendall(("GET %s HTTP/1.1\r\nHost: %s:%d\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                           "Sec-WebSocket-Key: %s\r\nSec-WebSocket-Version: 13\r\n\r\n" % (path, host, port, key)).encode())
        self.buf = bytearray()
        while b"\r\n\r\n" not in self.buf:
            chunk = self.sock.recv(4096)
            if not chunk:
                raise ConnectionError("WebSocket upgrade: the server closed the connection")
            self.buf += chunk
        head, _, rest = bytes(self.buf).partition(b"\r\n\r\n")
        self.buf = bytearray(rest)
        status = head.split(b"\r\n", 1)[0]
        if b" 101 " not in status + b" ":
            raise ConnectionError("WebSocket upgrade refused: %r" % status)
        self.sock.settimeout(None)
        self.lock = threading.Lock()
        self.message = b""   # a fragmented message so far
        self.kind = None

    def _frame(self, opcode, payload):
        head = bytes([0x80 | opcode])
        n = len(payload)
        if n < 126:
            head += bytes([0x80 | n])
        elif n < 65536:
            head += bytes([0x80 | 126]) + struct.pack("!H", n)
        else:
            head += bytes([0x80 | 127]) + struct.pack("!Q", n)
        mask = os.urandom(4)
        masked = bytes(b ^ mask[i % 4] for i, b in enumerate(payload)) if n < 64 else _mask(payload, mask)
        with self.lock:
            self.sock.sendall(head + mask + masked)

    def send(self, text):
        self._frame(0x1, text.encode("utf-8"))

    def send_raw(self, opcode, payload):
        self._frame(opcode, payload)

    def _need(self, n, deadline):
        while len(self.buf) < n:
            _wait_readable(self.sock, deadline)
            chunk = self.sock.recv(max(262144, n - len(self.buf)))
            if not chunk:
                raise EOFError
            self.buf += chunk

    def receive(self, deadline=None):
        """The next text message (str) or binary message (bytes); None at the end; TimeoutError
        at `deadline` (a frame is taken from the buffer only once it is whole: nothing is lost)."""
        try:
            while True:
                self._need(2, deadline)
                b0, b1 = self.buf[0], self.buf[1]
                opcode, n, off = b0 & 0x0F, b1 & 0x7F, 2
                if n == 126:
                    self._need(4, deadline)
                    n, off = struct.unpack_from("!H", self.buf, 2)[0], 4
                elif n == 127:
                    self._need(10, deadline)
                    n, off = struct.unpack_from("!Q", self.buf, 2)[0], 10
                self._need(off + n, deadline)
                payload = bytes(self.buf[off:off + n])
                del self.buf[:off + n]
                if opcode == 0x8:
                    return None
                if opcode == 0x9:
                    self._frame(0xA, payload)
                    continue
                if opcode == 0xA:
                    continue
                if opcode in (0x1, 0x2):
                    self.kind = opcode
                self.message += payload
                if b0 & 0x80:
                    message, self.message = self.message, b""
                    return message.decode("utf-8", "replace") if self.kind == 0x1 else message
        except TimeoutError:
            raise
        except (EOFError, OSError, ValueError):
            return None

    def close(self):
        try:
            self._frame(0x8, struct.pack("!H", 1000))
        except OSError:
            pass
        self.sock.close()


def _mask(payload, mask):
    m = int.from_bytes(mask * ((len(payload) + 3) // 4), "little")
    p = int.from_bytes(payload + b"\0" * ((4 - len(payload) % 4) % 4), "little")
    return (p ^ m).to_bytes(len(payload) + (4 - len(payload) % 4) % 4, "little")[:len(payload)]


def decode_binary_frame(data):
    """A binary frame (docs/protocol.md, "Binary frames") as a dict."""
    if data[:4] != b"TGF1":
        raise ValueError("not a turtlegas binary frame")
    version, flags, seq, n, m, tail = struct.unpack_from("<HHIIII", data, 4)
    t, wall, step = struct.unpack_from("<ddQ", data, 24)
    off = 48
    index = None
    if flags & 4:  # a region: the balls' indices first
        index = struct.unpack_from("<%dI" % n, data, off)
        off += 4 * n
    pos = struct.unpack_from("<%df" % (2 * n), data, off)
    off += 8 * n
    vel = None
    if flags & 2:
        vel = struct.unpack_from("<%df" % (2 * n), data, off)
        off += 8 * n
    turtles = struct.unpack_from("<%df" % (3 * m), data, off)
    off += 12 * m
    tflags = struct.unpack_from("<%dI" % m, data, off)
    off += 4 * m
    rest = json.loads(data[off:off + tail].decode("utf-8"))
    return {"version": version, "paused": bool(flags & 1), "seq": seq, "t": t, "wall": wall, "step": step,
            "index": index, "pos": pos, "vel": vel, "turtles": turtles, "turtle_flags": tflags, "tail": rest,
            "size": off + tail}


# ---- the world ----------------------------------------------------------------------------------

_NOTHING = object()


class Mailbox:
    """Frames or notices as they arrive: get() reads the connection while it waits (queue-like;
    queue.Empty at the timeout)."""

    def __init__(self, world):
        self._world = world
        self._items = collections.deque()

    def get(self, block=True, timeout=None):
        def take():
            return self._items.popleft() if self._items else _NOTHING
        got = self._world._wait(take, timeout if block else 0.0, closed_value=None)
        if got is _NOTHING:
            raise queue.Empty
        return got

    def get_nowait(self):
        return self.get(block=False)

    def qsize(self):
        return len(self._items)

    def empty(self):
        return not self._items


class World:
    """One connection to a served world. Thread-safe: any thread may send and wait."""

    def __init__(self, transport, token=None, background=False):
        self._t = transport
        self._cv = threading.Condition()
        self._reading = False     # a thread is reading the connection for everyone
        self._next_id = 0
        self._replies = {}        # id -> the reply, until its requester takes it
        self._turtles = {}        # turtle id -> RemoteTurtle
        self._closed = False
        self.bye = None
        self.status = None
        self.frames = Mailbox(self)   # frames and snapshots, when subscribed (oldest first)
        self.notices = Mailbox(self)  # status, world and unsolicited errors
        self._reader = None
        if background:
            self._reader = threading.Thread(target=self._read_on, daemon=True)
            self._reader.start()
        hello = {"type": "hello", "protocol": PROTOCOL}
        if token is not None:
            hello["token"] = token
        self.welcome = self.request(hello)
        self.status = self.welcome.get("status")

    @classmethod
    def connect(cls, host="127.0.0.1", port=8081, token=None, timeout=10.0, background=False):
        """Over TCP lines (the server's --line-port)."""
        return cls(_Lines(host, port, timeout), token, background)

    @classmethod
    def connect_ws(cls, host="127.0.0.1", port=8080, token=None, timeout=10.0, path="/ws", background=False):
        """Over the WebSocket at ws://host:port/ws."""
        return cls(_WebSocket(host, port, path, timeout), token, background)

    # -- plumbing --
    def _dispatch(self, text):
        """Files one incoming message where its reader will look (under self._cv)."""
        if isinstance(text, bytes):
            self.frames._items.append(decode_binary_frame(text))
            return
        try:
            m = json.loads(text)
        except ValueError:
            return
        kind = m.get("type")
        if kind == "bye":
            self.bye = m
            return
        if kind in ("frame", "snapshot") and "id" not in m:
            self.frames._items.append(m)
            return
        if kind in ("touch", "message", "fault") and "id" not in m:
            t = self._turtles.get(m.get("turtle"))
            if t is not None:
                t._inbox.append(m)
            return
        if kind == "status":
            self.status = m.get("status")
        rid = m.get("id")
        if rid is not None and rid in self._replies and self._replies[rid] is None:
            self._replies[rid] = m
        else:
            self.notices._items.append(m)

    def _wait(self, take, timeout=None, closed_value=_NOTHING):
        """Until take() (called under the lock) gives something other than _NOTHING. While no
        other thread reads the connection, this one does, filing what it reads for the others.
        At the timeout: _NOTHING; when the connection closes first: closed_value, or Closed."""
        deadline = None if timeout is None else time.monotonic() + timeout
        with self._cv:
            while True:
                got = take()
                if got is not _NOTHING:
                    return got
                if self._closed:
                    if closed_value is _NOTHING:
                        raise Closed(self.bye)
                    return _NOTHING if closed_value is None else closed_value
                if not self._reading:
                    self._reading = True
                    break
                left = None if deadline is None else deadline - time.monotonic()
                if left is not None and left <= 0:
                    return _NOTHING
                self._cv.wait(left)
        try:
            while True:
                try:
                    text = self._t.receive(deadline)
                except TimeoutError:
                    return _NOTHING
                with self._cv:
                    if text is None:
                        self._closed = True
                        if closed_value is _NOTHING:
                            raise Closed(self.bye)
                        return _NOTHING if closed_value is None else closed_value
                    self._dispatch(text)
                    got = take()
                    if got is not _NOTHING:
                        return got
                    self._cv.notify_all()  # it was another thread's
        finally:
            with self._cv:
                self._reading = False
                self._cv.notify_all()  # one of the waiters reads on

    def _read_on(self):
        try:
            self._wait(lambda: _NOTHING)
        except Closed:
            pass

    def wait_closed(self, timeout=None):
        """Reads (filing what comes) until the server closes the connection; whether it did."""
        self._wait(lambda: True if self._closed else _NOTHING, timeout, closed_value=True)
        return self._closed

    @property
    def closed(self):
        return self._closed

    def send(self, message):
        """Sends a message as is (no id added); returns nothing."""
        self._t.send(json.dumps(message))

    def request(self, message, timeout=None):
        """Sends `message` with a fresh id and returns the reply; raises ServerError on an error
        reply, Closed when the server closes first."""
        with self._cv:
            if self._closed:
                raise Closed(self.bye)
            self._next_id += 1
            rid = self._next_id
            self._replies[rid] = None
        m = dict(message)
        m["id"] = rid
        self._t.send(json.dumps(m))

        def take():
            r = self._replies.get(rid)
            if r is None:
                return _NOTHING
            del self._replies[rid]
            return r
        try:
            reply = self._wait(take, timeout)
        finally:
            with self._cv:
                self._replies.pop(rid, None)
        if reply is _NOTHING:
            raise TimeoutError("no reply to %s within %s s" % (message.get("type"), timeout))
        if reply.get("type") == "error":
            raise ServerError(reply)
        return reply

    def close(self):
        self._t.close()
        if self._reader is not None:
            self._reader.join(timeout=5)

    # -- the API --
    def claim(self, turtle, takeover=False):
        msg = {"type": "claim", "turtle": turtle}
        if takeover:
            msg["takeover"] = True
        reply = self.request(msg)
        t = RemoteTurtle(self, turtle, reply.get("sensors", []), reply.get("senses", []))
        self._turtles[turtle] = t
        return t

    def release(self, turtle):
        self._turtles.pop(turtle, None)
        return self.request({"type": "release", "turtle": turtle})

    def pause(self):
        return self.request({"type": "pause"})

    def resume(self):
        return self.request({"type": "resume"})

    def step(self, steps=1):
        return self.request({"type": "step", "steps": steps})

    def speed(self, factor):
        return self.request({"type": "speed", "factor": factor})

    def run_until(self, t):
        return self.request({"type": "run_until", "t": t})

    # World changes (docs/protocol.md, "World changes"): answered at the boundary they are made at.
    # In lockstep a boundary that waits for one of this connection's turtles makes them there and
    # then, so calling them between a turtle's commands cannot hold the world up.
    def add_wall(self, wall_id, start, end):
        return self.request({"type": "add_wall", "wall": {"id": wall_id, "from": list(start), "to": list(end)}})

    def spawn(self, ball=None, turtle=None):
        """Adds a body: one world-file entry, e.g. spawn(ball={"id": "b9", "pos": [50, 50], "radius": 4})."""
        if (ball is None) == (turtle is None):
            raise ValueError("spawn(ball=...) or spawn(turtle=...), one of them")
        return self.request({"type": "spawn", "ball": dict(ball)} if ball is not None else {"type": "spawn", "turtle": dict(turtle)})

    def remove(self, body):
        return self.request({"type": "remove", "body": body})

    def teleport(self, body, pos, heading=None, vel=None):
        """Moves a ball (vel: its new velocity, else kept) or a turtle (heading in degrees, else kept)."""
        m = {"type": "teleport", "body": body, "pos": list(pos)}
        if heading is not None:
            m["heading"] = heading
        if vel is not None:
            m["vel"] = list(vel)
        return self.request(m)

    def save(self, file):
        return self.request({"type": "save", "file": file})

    # Views (display windows, docs/viewer.md): a dict as in the world file's "views" list.
    def view_open(self, view):
        """Opens a view, e.g. {"id": "v1", "follow": "t1", "size": [200, 150], "rotate": True}."""
        return self.request({"type": "view_open", "view": dict(view)})

    def view_change(self, view_id, **changes):
        """Changes the keys given, e.g. view_change("v1", size=[300, 200])."""
        return self.request({"type": "view_change", "view": dict(changes, id=view_id)})

    def view_close(self, view_id):
        return self.request({"type": "view_close", "view": view_id})

    def load(self, file):
        return self.request({"type": "load", "file": file})

    def subscribe(self, rate=30, events=(), fmt="json", velocities=True, region=None):
        ev = events if isinstance(events, str) else list(events)
        m = {"type": "subscribe", "rate": rate, "events": ev, "format": fmt, "velocities": velocities}
        if region is not None:
            m["region"] = list(region)
        return self.request(m)

    def snapshot(self):
        return self.request({"type": "snapshot"})

    def stats(self):
        return self.request({"type": "stats"})

    def ping(self):
        return self.request({"type": "ping"})

    @staticmethod
    def run_turtles(programs):
        """Runs each `program(turtle)` of {turtle: program} in a thread of its own; returns when
        all have ended (Closed, the server's stop, ends them quietly). Returns their exceptions."""
        errors = {}

        def body(t, p):
            try:
                p(t)
            except Closed:
                pass
            except BaseException as e:  # reported to the caller
                errors[t.id] = e

        threads = [threading.Thread(target=body, args=(t, p), daemon=True) for t, p in programs.items()]
        for th in threads:
            th.start()
        for th in threads:
            th.join()
        return errors


class RemoteTurtle:
    """A claimed turtle. Its commands block until their result, like the C++ Turtle's."""

    def __init__(self, world, turtle_id, sensors, senses=()):
        self.world = world
        self.id = turtle_id
        self.sensors = sensors  # the touch arcs' names
        self.senses = list(senses)  # range sensors: {"name", "bearings", "range"}, for sense(name)
        self._inbox = collections.deque()  # touches, messages, faults (filed by World._dispatch)
        self.touches = []    # every touch interrupt, in order
        self.messages = []   # every message, in order
        self.fault = None
        self.state = {}
        self._on_touch = None
        self._on_message = None

    def on_touch(self, handler):
        self._on_touch = handler

    def on_message(self, handler):
        self._on_message = handler

    def _deliver(self):
        while True:
            try:
                m = self._inbox.popleft()
            except IndexError:
                return
            if m["type"] == "touch":
                touch = Touch(m["touch"])
                self.touches.append(touch)
                if self._on_touch:
                    self._on_touch(touch)
            elif m["type"] == "message":
                self.messages.append(m)
                if self._on_message:
                    self._on_message(m["data"])
            elif m["type"] == "fault":
                self.fault = m["message"]

    def _command(self, message):
        message["turtle"] = self.id
        try:
            reply = self.world.request(message)
        finally:
            self._deliver()
        self.state = reply.get("state", {})
        return Result(reply)

    def forward(self, amount):
        return self._command({"type": "forward", "amount": amount})

    def back(self, amount):
        return self._command({"type": "back", "amount": amount})

    def left(self, degrees):
        return self._command({"type": "left", "amount": degrees})

    def right(self, degrees):
        return self._command({"type": "right", "amount": degrees})

    def wait(self, seconds):
        return self._command({"type": "wait", "amount": seconds})

    def arc(self, radius, degrees):
        """Drives along a circle of `radius` units through `degrees` of turn (positive right,
        clockwise; negative left). The result's done is the distance along the arc."""
        return self._command({"type": "arc", "radius": radius, "degrees": degrees})

    def drive(self, v, omega, seconds):
        """Drives for `seconds` at `v` units/s while turning at `omega` degrees/s (positive right)."""
        return self._command({"type": "drive", "v": v, "omega": omega, "seconds": seconds})

    def wheels(self, left, right, seconds):
        """Differential drive: the wheels at `left` and `right` units/s for `seconds`, the
        world file's "axle" apart."""
        return self._command({"type": "wheels", "left": left, "right": right, "seconds": seconds})

    def yield_(self):
        return self._command({"type": "yield"})

    def pen_up(self):
        return self._command({"type": "pen", "down": False})

    def pen_down(self, mode="line"):
        return self._command({"type": "pen", "down": True, "mode": mode})

    def sense(self, sensor):
        """Reads range sensor `sensor` (the turtle's "senses" in the world file) at the next control
        boundary, taking no simulated time: a list of Reading, one per ray, as Turtle::scan."""
        r = self._command({"type": "sense", "sensor": sensor})
        return [Reading(d) for d in r.reply.get("readings", [])]

    def camera(self, sensor):
        """Reads line camera `sensor` (a "camera" under the turtle's "senses") at the next control
        boundary, taking no simulated time: a list of Reading, one per pixel left to right, each
        with its colour, as Turtle::camera."""
        r = self._command({"type": "camera", "sensor": sensor})
        return [Reading(d) for d in r.reply.get("readings", [])]

    @property
    def heading(self):
        return self.state.get("heading")

    @property
    def odometer(self):
        return self.state.get("odometer")
