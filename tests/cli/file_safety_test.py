#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Nothing lost (issue 29, the file-safety items; docs/cli.md, "Output files"):

- `run --record R` leaves an existing R as it was when the world or an option is refused, and
  while the run goes on (the recording is R.partial until it is whole);
- a checkpoint holds the hash of the world bytes that ran, read once at load: a world edited
  during a --checkpoint-every run is refused on --resume, the one that ran is accepted; a damaged
  checkpoint is refused as damaged (exit 2), not replayed to a "not deterministic" error; a crash
  after a periodic checkpoint does not report "no outputs were written";
- a sweep's runs all run the spec and world the sweep read at its start, whatever is edited on
  disk meanwhile;
- a journal whose first (header) line is damaged keeps its runs: the header is written twice;
- a journal line that names a run but is not its result (another seed, no overrides) is not
  taken as one: that run runs again;
- a sweep summary pointer that no result line has is an error (exit 2), not a column of "-";
- outputs that are inputs: `sweep --out`, `tag --json`, `test --junit` refuse to overwrite the
  spec or world they read;
- a full disk (a 64 KiB tmpfs, mounted here when run as root, else skipped with the reason): the
  sweep journal, `render`, a periodic checkpoint each say "No space left on device" and where,
  exit non-zero, and keep what was whole (the journal's lines, the --events log).

Usage: file_safety_test.py [--turtlegas BIN] [--test-plugin SO] [CASE ...]; every wait is bounded."""

import argparse
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.environ.get("TURTLEGAS", os.path.join(ROOT, "build", "release", "turtlegas"))
TEST_PLUGIN = None  # tests/cli/test_plugin.cpp, built (its crasher)
TMP = None


def path(*names):
    return os.path.join(TMP, *names)


def read(p):
    with open(p, "rb") as f:
        return f.read()


def write(p, data):
    with open(p, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def run(*args, ok=None, timeout=300, cwd=None):
    p = subprocess.run([BIN, *map(str, args)], capture_output=True, timeout=timeout, cwd=cwd or TMP)
    if ok is not None and p.returncode not in ok:
        raise AssertionError("%s exited %d (wanted %s)\nstdout: %s\nstderr: %s" %
                             (args, p.returncode, ok, p.stdout.decode(errors="replace")[-2000:],
                              p.stderr.decode(errors="replace")[-2000:]))
    return p


def wait_for(cond, seconds, what):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if cond():
            return
        time.sleep(0.02)
    raise AssertionError("waited %g s for %s" % (seconds, what))


def gas_world(name, balls=400, extra=None):
    """A copy of worlds/gas.json (a few hundred balls: each run takes a noticeable time)."""
    w = json.loads(read(os.path.join(ROOT, "worlds", "gas.json")))
    if extra:
        w.update(extra)
    write(path(name), json.dumps(w, indent=1) + "\n")
    return path(name)


# ---- 1. run --record ------------------------------------------------------------------------------

def check_record_not_truncated():
    world = gas_world("rec_world.json")
    rec = path("r.tgrec")
    precious = b"a recording the user keeps\n"
    write(rec, precious)
    write(path("bad.json"), b'{"format": "turtlegas-world/1", "arena": ')
    p = run("run", path("bad.json"), "--until", "1", "--record", rec, ok=(2,))
    assert read(rec) == precious, "a refused world truncated --record's file: %r" % read(rec)[:80]
    # An option refused once the world is loaded (--svg-trails needs --svg).
    p = run("run", world, "--until", "1", "--record", rec, "--svg-trails", "0.5", ok=(2,))
    assert read(rec) == precious, "a refused option left --record's file as %r" % read(rec)[:80]
    assert not os.path.exists(rec + ".partial"), "a refused run left R.partial"
    # A whole run replaces it.
    run("run", world, "--until", "0.5", "--record", rec, ok=(0,))
    assert read(rec).startswith(b'{"format":"turtlegas-recording/'), read(rec)[:80]
    assert not os.path.exists(rec + ".partial"), "R.partial left after a whole run"
    whole = read(rec)
    # While a run goes on, and after it is killed, R is the recording it replaces; R.partial the
    # new one so far, readable up to its last keyframe.
    proc = subprocess.Popen([BIN, "run", world, "--until", "100000", "--record", rec, "--keyframe-seconds", "0.05"],
                            stderr=subprocess.DEVNULL, cwd=TMP)
    try:
        wait_for(lambda: os.path.exists(rec + ".partial") and read(rec + ".partial").count(b'\n{"keyframe":') >= 3,
                 120, "R.partial with 3 keyframes")
        assert read(rec) == whole, "R changed while the run that replaces it goes on"
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    assert read(rec) == whole, "a killed run damaged R"
    p = run("render", rec + ".partial", "--at", "0.05", "--out", path("killed.svg"), ok=(0,))
    assert b"recovered" in p.stderr, p.stderr


# ---- 2. checkpoints hash the world at load --------------------------------------------------------

def check_checkpoint_world_hash():
    world = gas_world("ck_world.json")
    ran = read(world)
    ck = path("ck.json")
    proc = subprocess.Popen([BIN, "run", world, "--until", "1e6", "--checkpoint", ck, "--checkpoint-every", "0.01",
                             "--max-wall-seconds", "4"], stderr=subprocess.PIPE, cwd=TMP)
    try:
        wait_for(lambda: os.path.exists(ck), 60, "the first checkpoint")
        edited = json.loads(ran)
        edited["name"] = "edited while it ran"
        write(world, json.dumps(edited, indent=1) + "\n")
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 3, "the run should stop at --max-wall-seconds (exit 3): %d %s" % (proc.returncode, err)
    t = json.loads(read(ck))["t"]
    p = run("run", world, "--resume", ck, "--until", repr(t + 0.01), ok=(2,))
    assert b"not the one the checkpoint was written for" in p.stderr, p.stderr
    write(world, ran)
    run("run", world, "--resume", ck, "--until", repr(t + 0.01), ok=(0,))


def check_checkpoint_damaged():
    world = gas_world("cd_world.json")
    ck = path("cd.json")
    run("run", world, "--until", "0.2", "--checkpoint", ck, ok=(0,))
    c = json.loads(read(ck))
    c["events"] += 1
    write(ck, json.dumps(c, indent=2) + "\n")
    p = run("run", world, "--resume", ck, "--until", "0.3", ok=(2,))
    assert b"damaged" in p.stderr and b"not deterministic" not in p.stderr, p.stderr


def check_crash_report():
    if not TEST_PLUGIN:
        print("file_safety_test: crash_report: SKIPPED (no --test-plugin)")
        return
    world = path("crash_world.json")
    write(world, json.dumps({"format": "turtlegas-world/1", "arena": {"width": 200, "height": 200, "boundary": "walls"},
                             "turtles": [{"id": "rogue", "pos": [100, 100], "controller": "crasher",
                                          "params": {"how": "null", "after": 0.5}}]}))
    ck = path("crash_ck.json")
    p = run("run", world, "--until", "5", "--plugin", TEST_PLUGIN, "--checkpoint", ck, "--checkpoint-every", "0.1")
    err = p.stderr.decode(errors="replace")
    assert p.returncode != 0 and "turtle 'rogue'" in err, err
    assert os.path.exists(ck), "no periodic checkpoint before the crash"
    assert "no outputs were written" not in err and "are whole" in err, err


# ---- 3. a sweep's runs use the parent's bytes -----------------------------------------------------

def check_sweep_world_edited():
    world = gas_world("sw_world.json", extra={"name": "as the sweep began"})
    spec = path("sw_spec.json")
    write(spec, json.dumps({"format": "turtlegas-sweep/1", "world": "sw_world.json", "until": 2.0,
                            "seeds": {"count": 6}}))
    out = path("sw.results.jsonl")
    proc = subprocess.Popen([BIN, "sweep", spec, "--out", out, "--jobs", "1", "--quiet"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, cwd=TMP)
    try:
        wait_for(lambda: os.path.exists(out + ".partial") and read(out + ".partial").count(b"\n") >= 2, 120,
                 "the first run in the journal")
        w = json.loads(read(world))
        w["name"] = "edited during the sweep"
        w["balls"] = w["balls"][: len(w["balls"]) // 2] if isinstance(w.get("balls"), list) else w.get("balls")
        write(world, json.dumps(w))
        write(spec, json.dumps({"format": "turtlegas-sweep/1", "world": "sw_world.json", "until": 0.5,
                                "seeds": {"count": 6}}))
        o, e = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, "sweep exited %d: %s" % (proc.returncode, e.decode(errors="replace"))
    lines = [json.loads(l) for l in read(out).splitlines()]
    names = {l["stats"]["name"] for l in lines[1:]}
    untils = {l["stats"]["until"] for l in lines[1:]}
    assert names == {"as the sweep began"} and untils == {2.0}, \
        "one results file with runs of two worlds or specs: names %s, until %s" % (names, untils)
    assert len(lines) == 7, len(lines)


def check_sweep_summary_misspelt():
    gas_world("sm_world.json")
    spec = path("sm_spec.json")
    write(spec, json.dumps({"format": "turtlegas-sweep/1", "world": "sm_world.json", "until": 0.1, "seeds": [1, 2],
                            "summary": ["/stats/colisions", "/stats/collisions"]}))
    p = run("sweep", spec, "--out", path("sm.jsonl"), "--quiet", ok=(2,))
    assert b"/stats/colisions" in p.stderr and b"is in no result line" in p.stderr, p.stderr
    assert b'"/stats/collisions"' not in p.stderr, p.stderr
    # Refused before any run (issue 35): no runs were wasted on a table with a column of "-".
    assert not os.path.exists(path("sm.jsonl")) and not os.path.exists(path("sm.jsonl.partial")), "runs were made"


def check_sweep_journal_forged():
    gas_world("jf_world.json")
    spec = path("jf_spec.json")
    write(spec, json.dumps({"format": "turtlegas-sweep/1", "world": "jf_world.json", "until": 0.2, "seeds": [1, 2]}))
    out = path("jf.jsonl")
    run("sweep", spec, "--out", out, "--quiet", "--timeout", "0.000001", ok=(1,))  # a journal, its header only
    header = read(out + ".partial").splitlines()[0]
    forged = [json.dumps({"run": 0, "seed": 999, "overrides": {}, "stats": {"forged": True}}),
              json.dumps({"run": 1, "stats": {"forged": True}})]
    write(out + ".partial", header + b"\n" + "\n".join(forged).encode() + b"\n")
    p = run("sweep", spec, "--out", out, "--quiet", ok=(0,))
    lines = [json.loads(l) for l in read(out).splitlines()[1:]]
    assert [l.get("seed") for l in lines] == [1, 2] and all("forged" not in l["stats"] for l in lines), lines


def check_sweep_journal_damaged_header():
    gas_world("jh_world.json")
    spec = path("jh_spec.json")
    write(spec, json.dumps({"format": "turtlegas-sweep/1", "world": "jh_world.json", "until": 0.2, "seeds": [1, 2, 3]}))
    whole = path("jh_whole.jsonl")
    run("sweep", spec, "--out", whole, "--quiet", ok=(0,))
    out = path("jh.jsonl")
    run("sweep", spec, "--out", out, "--quiet", "--timeout", "0.000001", ok=(1,))  # a journal, its header only
    head = read(out + ".partial").splitlines()
    runs = read(whole).splitlines()[1:3]  # runs 0 and 1, as a journal holds them
    write(out + ".partial", b'{"fingerpr\n' + b"\n".join(head[1:] + runs) + b"\n")  # the first line damaged
    p = run("sweep", spec, "--out", out)
    assert p.returncode == 0, "a journal with one damaged header line was refused: %s" % p.stderr
    assert b"resuming: 2 of 3" in p.stderr, p.stderr
    assert read(out) == read(whole)


# ---- 4. outputs that are inputs -------------------------------------------------------------------

def check_outputs_that_are_inputs():
    world = gas_world("in_world.json")
    spec = path("in_spec.json")
    spec_text = json.dumps({"format": "turtlegas-sweep/1", "world": "in_world.json", "until": 0.1, "seeds": [1]})
    write(spec, spec_text)
    before = read(world)
    for target, what in ((spec, "the sweep spec"), (world, "the world file")):
        p = run("sweep", spec, "--out", target, "--quiet", ok=(2,))
        assert read(spec) == spec_text.encode() and read(world) == before, "sweep --out overwrote " + what
        assert b"--out" in p.stderr, p.stderr
    tag = path("tag_world.json")
    shutil.copy(os.path.join(ROOT, "worlds", "tag.json"), tag)
    tag_bytes = read(tag)
    p = run("tag", tag, "--controllers", "tag_chaser,tag_evader", "--rounds", "1", "--until", "1", "--json", tag,
            ok=(2,))
    assert read(tag) == tag_bytes, "tag --json overwrote its world"
    test_world = path("test_world.json")
    shutil.copy(os.path.join(ROOT, "worlds", "tests", sorted(os.listdir(os.path.join(ROOT, "worlds", "tests")))[0]),
                test_world)
    test_bytes = read(test_world)
    p = run("test", test_world, "--junit", test_world, ok=(2,))
    assert read(test_world) == test_bytes, "test --junit overwrote its world"


# ---- 5. a full disk -------------------------------------------------------------------------------

class SmallDisk:
    """A 64 KiB tmpfs at path("full"), filled but for `room` bytes."""

    def __init__(self, room=0):
        self.dir = path("full")
        self.room = room

    def __enter__(self):
        os.makedirs(self.dir, exist_ok=True)
        subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", self.dir], check=True)
        try:
            with open(os.path.join(self.dir, "filler"), "wb") as f:
                f.write(b"x" * (64 * 1024 - self.room))
        except OSError:
            pass
        return self.dir

    def __exit__(self, *a):
        subprocess.run(["umount", "-l", self.dir], check=False)


def full_disk_skip():
    if os.geteuid() != 0:
        return "not root: cannot mount a small tmpfs"
    probe = path("probe")
    os.makedirs(probe, exist_ok=True)
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", probe], capture_output=True)
    if r.returncode != 0:
        return "cannot mount a tmpfs here (%s)" % r.stderr.decode(errors="replace").strip()
    subprocess.run(["umount", probe])
    return None


def check_full_disk_journal():
    world = gas_world("fd_world.json", balls=50)
    spec = path("fd_spec.json")
    write(spec, json.dumps({"format": "turtlegas-sweep/1", "world": "fd_world.json", "until": 0.2,
                            "seeds": {"count": 40}}))
    with SmallDisk(room=6000) as d:
        out = os.path.join(d, "fd.results.jsonl")
        p = run("sweep", spec, "--out", out, "--quiet")
        err = p.stderr.decode(errors="replace")
        assert p.returncode != 0, "a sweep whose journal hit a full disk exited 0: " + err
        assert "No space left on device" in err and "fd.results.jsonl.partial" in err, err
        assert not os.path.exists(out), "a results file on a full disk"
        data = read(out + ".partial")
        assert data.endswith(b"\n"), "the journal ends with a cut line"
        lines = data.splitlines()
        for l in lines:
            json.loads(l)
        assert len(lines) >= 2, "no run kept in the journal"


def check_full_disk_render():
    world = gas_world("fr_world.json", balls=50)
    with SmallDisk() as d:
        for out in ("x.png", "x.svg"):
            p = run("render", world, "--at", "0", "--out", os.path.join(d, out), ok=(1,))
            err = p.stderr.decode(errors="replace")
            assert "No space left on device" in err and out in err, err
            assert "could not encode" not in err, err


def check_full_disk_checkpoint():
    world = gas_world("fc_world.json", balls=50)
    events = path("fc.events.jsonl")
    state = path("fc.state.json")
    with SmallDisk() as d:
        ck = os.path.join(d, "ck.json")
        p = run("run", world, "--until", "1", "--checkpoint", ck, "--checkpoint-every", "0.25", "--events", events,
                "--state-out", state)
        err = p.stderr.decode(errors="replace")
        assert p.returncode == 1, "a run whose checkpoints failed exited %d: %s" % (p.returncode, err)
        assert "No space left on device" in err and "ck.json" in err, err
    log = read(events)
    assert log.endswith(b"\n") and len(log) > 0, "the events log was discarded or cut"
    for l in log.splitlines():
        json.loads(l)
    ref = path("fc.ref.jsonl")
    run("run", world, "--until", "1", "--events", ref, ok=(0,))
    assert read(ref) == log, "the events log of the run with failing checkpoints is not the whole run's"
    assert json.loads(read(state))["t"] == 1.0


def check_killed_temporaries():
    """A run killed with SIGKILL leaves its event log in a hidden temporary (.ev.jsonl.tmp-PID); the next
    run writing that file keeps it as ev.jsonl.killed-PID, says so, and leaves no hidden temporary
    (before: they piled up, hidden)."""
    d = path("killed")
    os.makedirs(d, exist_ok=True)
    w = gas_world("killed/w.json")
    p = subprocess.Popen([BIN, "run", w, "--until", "1e9", "--events", "ev.jsonl", "--state-out", "st.json"], cwd=d,
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    hidden = os.path.join(d, ".ev.jsonl.tmp-%d" % p.pid)
    try:
        wait_for(lambda: os.path.exists(hidden) and os.path.getsize(hidden) > 10000, 60, "the event log to grow")
    finally:
        p.kill()
        p.wait()
    written = read(hidden)
    r = run("run", w, "--until", "0.1", "--events", "ev.jsonl", "--state-out", "st.json", ok=(0,), cwd=d)
    err = r.stderr.decode()
    kept = os.path.join(d, "ev.jsonl.killed-%d" % p.pid)
    assert os.path.exists(kept) and read(kept) == written, "the killed run's event log was not kept as %s" % kept
    assert "a run that was killed (process %d, gone)" % p.pid in err, err
    left = [f for f in os.listdir(d) if ".tmp-" in f]
    assert not left, "hidden temporaries left: %s" % left


CASES = {
    "killed_temporaries": check_killed_temporaries,
    "record": check_record_not_truncated,
    "checkpoint": check_checkpoint_world_hash,
    "checkpoint_damaged": check_checkpoint_damaged,
    "crash_report": check_crash_report,
    "sweep_edited": check_sweep_world_edited,
    "sweep_summary": check_sweep_summary_misspelt,
    "sweep_journal_forged": check_sweep_journal_forged,
    "sweep_journal_header": check_sweep_journal_damaged_header,
    "outputs_inputs": check_outputs_that_are_inputs,
    "full_journal": check_full_disk_journal,
    "full_render": check_full_disk_render,
    "full_checkpoint": check_full_disk_checkpoint,
}


def main():
    global BIN, TMP, TEST_PLUGIN
    ap = argparse.ArgumentParser()
    ap.add_argument("--turtlegas", default=BIN)
    ap.add_argument("--test-plugin", default=None)
    ap.add_argument("cases", nargs="*")
    a = ap.parse_args()
    BIN = os.path.abspath(a.turtlegas)
    TEST_PLUGIN = a.test_plugin and os.path.abspath(a.test_plugin)
    TMP = tempfile.mkdtemp(prefix="turtlegas-file-safety-")
    failed = []
    skip = None
    try:
        for name in a.cases or CASES:
            if name.startswith("full_"):
                skip = skip or full_disk_skip()
                if skip:
                    print("file_safety_test: %s: SKIPPED (%s)" % (name, skip))
                    continue
            try:
                CASES[name]()
                print("file_safety_test: %s: ok" % name)
            except AssertionError as e:
                failed.append(name)
                print("file_safety_test: %s: FAILED: %s" % (name, e))
    finally:
        subprocess.run(["umount", "-l", path("full")], capture_output=True)
        shutil.rmtree(TMP, ignore_errors=True)
    if failed:
        print("file_safety_test: failed: " + ", ".join(failed))
        sys.exit(1)


if __name__ == "__main__":
    main()
