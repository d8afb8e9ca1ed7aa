#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The installed package as a controller author meets it (docs/controllers.md, "Install").

Installs the build tree into a temporary prefix with `cmake --install`, then:
  - the program there prints its version and runs a world;
  - every installed header compiles on its own, with the SDK's flags;
  - the example plugin, copied out of the prefix as an out-of-tree project (the <= 10-line
    CMakeLists.txt that docs/controllers.md shows), configures with find_package(turtlegas), builds
    with turtlegas_add_plugin's flags and runs under the installed program;
  - the same plugin built with `pkg-config --cflags --libs turtlegas` gives the same event log;
  - the Python module (when built) imports from where it was installed and runs a world.
Exits non-zero with a message on the first thing that is wrong.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from viewer_page import check_installed_viewer  # noqa: E402


def fail(msg):
    print("install_test: FAIL: " + msg, file=sys.stderr)
    sys.exit(1)


def run(cmd, **kw):
    r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)
    if r.returncode != 0:
        fail("{} exited with {}\nstdout:\n{}\nstderr:\n{}".format(" ".join(map(str, cmd)), r.returncode, r.stdout[-3000:],
                                                              r.stderr[-3000:]))
    return r


def check_python_package(build, prefix, world):
    """The Python module, when the build made it: installed under lib/python3.X/dist-packages (the
    place Debian's python3 reads under a prefix other than /usr, docs/python.md), it imports from
    there with its client and runs a world."""
    if not list((build / "python/turtlegas").glob("_turtlegas*.so")):
        return
    found = sorted(prefix.glob("lib/python3*/*-packages/turtlegas/__init__.py"))
    if len(found) != 1:
        fail("cmake --install put the Python package in {} places under lib/python3*/: {}".format(len(found), found))
    place = found[0].parent.parent
    script = ("import turtlegas, turtlegas.client, sys; w = turtlegas.World.load(sys.argv[1]); w.run(0.5); "
              "assert w.stats['collisions'] > 0; assert turtlegas.__file__.startswith(sys.argv[2]); print('ok')")
    r = run([sys.executable, "-c", script, world, place], env=dict(os.environ, PYTHONPATH=str(place)), cwd=prefix)
    if r.stdout.strip() != "ok":
        fail("the installed Python module printed " + repr(r.stdout))


def count_touches(events):
    return sum(1 for line in events.read_text().splitlines() if json.loads(line)["kind"] == "touch")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True, type=Path)
    ap.add_argument("--source", required=True, type=Path)
    ap.add_argument("--cmake", default="cmake")
    ap.add_argument("--cxx", default="c++")
    ap.add_argument("--generator", default="Ninja")
    a = ap.parse_args()

    tmp = Path(tempfile.mkdtemp(prefix="turtlegas-install-test-"))
    try:
        prefix = tmp / "prefix"
        run([a.cmake, "--install", a.build, "--prefix", prefix])
        for rel in ["bin/turtlegas", "include/turtlegas/turtle/turtle.hpp", "include/turtlegas/turtle/registry.hpp",
                    "include/turtlegas/sim/vec2.hpp", "share/turtlegas/worlds/tag.json",
                    "share/turtlegas/worlds/tests/box_bounce.json", "share/turtlegas/examples/feeler/CMakeLists.txt",
                    "share/doc/turtlegas/controllers.md", "share/doc/turtlegas/README.md"]:
            if not (prefix / rel).exists():
                fail("cmake --install did not install " + rel)
        libdirs = [d for d in ["lib", "lib64"] + ["lib/" + x.name for x in (prefix / "lib").glob("*-linux-gnu*")]
                   if (prefix / d / "cmake/turtlegas/turtlegasConfig.cmake").exists()]
        if not libdirs:
            fail("no lib*/cmake/turtlegas/turtlegasConfig.cmake under the prefix")
        libdir = prefix / libdirs[0]
        if not (libdir / "pkgconfig/turtlegas.pc").exists():
            fail("no turtlegas.pc beside the CMake package")

        turtlegas = prefix / "bin/turtlegas"
        version = run([turtlegas, "--version"]).stdout
        first = version.splitlines()[0] if version else ""
        if not first.startswith("turtlegas ") or "commit " not in version or "build " not in version:
            fail("turtlegas --version printed " + repr(version))

        check_installed_viewer(turtlegas, prefix / "share/turtlegas/web", prefix / "share/turtlegas/worlds/tag.json", fail)
        check_python_package(a.build, prefix, prefix / "share/turtlegas/worlds/gas.json")

        # Every installed header on its own: a missing include shows here, not in a user's build.
        headers = sorted((prefix / "include").rglob("*.hpp"))
        for h in headers:
            rel = h.relative_to(prefix / "include")
            src = tmp / ("h_" + rel.as_posix().replace("/", "_") + ".cpp")
            src.write_text('#include "{}"\n#include "{}"\n'.format(rel.as_posix(), rel.as_posix()))
            run([a.cxx, "-std=c++20", "-fsyntax-only", "-Wall", "-Wextra", "-Werror", "-I", prefix / "include", src])

        # The out-of-tree plugin, from the installed example (docs/controllers.md quotes the file).
        example = prefix / "share/turtlegas/examples/feeler"
        lists = (example / "CMakeLists.txt").read_text()
        if len(lists.splitlines()) > 10:
            fail("the example's CMakeLists.txt has {} lines, more than 10".format(len(lists.splitlines())))
        doc = (a.source / "docs/controllers.md").read_text()
        if lists.strip() not in doc:
            fail("docs/controllers.md does not show controllers/examples/CMakeLists.txt as it is")
        src = tmp / "feeler"
        shutil.copytree(example, src)
        build = src / "build"
        run([a.cmake, "-S", src, "-B", build, "-G", a.generator, "-DCMAKE_BUILD_TYPE=Release",
             "-DCMAKE_PREFIX_PATH=" + str(prefix), "-DCMAKE_EXPORT_COMPILE_COMMANDS=ON",
             "-DCMAKE_CXX_COMPILER=" + a.cxx])
        run([a.cmake, "--build", build])
        commands = json.loads((build / "compile_commands.json").read_text())
        line = commands[0]["command"]
        for flag in ["-fstack-clash-protection", "-ffp-contract=off", "-std=c++20", "-fPIC"]:
            if flag not in line:
                fail("turtlegas_add_plugin compiled without " + flag + ": " + line)
        if str(a.source) in line:
            fail("the out-of-tree plugin saw the source tree: " + line)
        plugin = build / "libfeeler.so"
        if not plugin.exists():
            fail("no libfeeler.so in " + str(build))

        listed = run([turtlegas, "controllers", "--plugin", plugin]).stdout
        if "feeler" not in listed:
            fail("turtlegas controllers --plugin libfeeler.so does not list feeler:\n" + listed)
        world = example / "feeler.json"
        events = tmp / "cmake.jsonl"
        run([turtlegas, "run", world, "--until", "60", "--plugin", plugin, "--events", events])
        touches = count_touches(events)
        if touches < 10:
            fail("the feeler touched {} times in 60 s; it follows walls by feel, so expected at least 10".format(touches))

        # The same plugin through pkg-config, without CMake.
        env = dict(os.environ, PKG_CONFIG_PATH=str(libdir / "pkgconfig"))
        flags = run(["pkg-config", "--cflags", "--libs", "turtlegas"], env=env).stdout.split()
        plugin2 = tmp / "libfeeler_pc.so"
        run([a.cxx, example / "feeler.cpp", *flags, "-o", plugin2])
        events2 = tmp / "pkgconfig.jsonl"
        run([turtlegas, "run", world, "--until", "60", "--plugin", plugin2, "--events", events2])
        if events.read_bytes() != events2.read_bytes():
            fail("the pkg-config build of the plugin gave another event log than the CMake build")
        print("install_test: ok: installed to a temporary prefix; {} headers compile alone; the out-of-tree "
              "plugin (CMake and pkg-config) ran, {} touches".format(len(headers), touches))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
