#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The Debian package: `cpack -G DEB` from the build tree, then, without a container:
  - the file is turtlegas_<version>_<arch>.deb and its fields are right;
  - unpacked into a clean directory tree (dpkg-deb -x), its program prints its version and checks
    and tests the worlds it ships (no LD_LIBRARY_PATH needed: every library it links is a
    system library from a Debian package, and the package depends on that package);
  - its Depends names the package of every shared library the program needs (NEEDED, resolved by
    the dynamic loader, owned per dpkg -S);
  - `apt-get install --simulate ./turtlegas_*.deb` accepts it (when apt-get is there).
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from viewer_page import check_installed_viewer  # noqa: E402


def fail(msg):
    print("deb_test: FAIL: " + msg, file=sys.stderr)
    sys.exit(1)


def run(cmd, ok=(0,), **kw):
    r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)
    if r.returncode not in ok:
        fail("{} exited with {}\nstdout:\n{}\nstderr:\n{}".format(" ".join(map(str, cmd)), r.returncode, r.stdout[-3000:],
                                                              r.stderr[-3000:]))
    return r


def owners(path):
    """The installed packages that own a library file: tried as the loader named it, then as it
    resolves, each with and without /usr (usrmerge makes /lib and /usr/lib the same directory)."""
    tries = []
    for p in [path, str(Path(path).resolve())]:
        tries.append(p)
        if p.startswith("/usr/lib/"):
            tries.append(p[len("/usr"):])
        elif p.startswith("/lib/"):
            tries.append("/usr" + p)
    for p in tries:
        r = subprocess.run(["dpkg", "-S", p], capture_output=True, text=True)
        if r.returncode == 0:
            first = r.stdout.splitlines()[0]  # "libfmt9:amd64: /usr/lib/x86_64-linux-gnu/libfmt.so.9.1.0"
            return {q.strip().split(":")[0] for q in first.rsplit(": ", 1)[0].split(",")}
    return set()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True, type=Path)
    ap.add_argument("--cpack", default="cpack")
    ap.add_argument("--version", required=True)
    a = ap.parse_args()
    for tool in ["dpkg-deb", "dpkg", "readelf", "ldd"]:
        if not shutil.which(tool):
            fail(tool + " is missing (Debian: dpkg, binutils, libc-bin)")

    tmp = Path(tempfile.mkdtemp(prefix="turtlegas-deb-test-"))
    try:
        run([a.cpack, "-G", "DEB", "--config", a.build / "CPackConfig.cmake", "-B", tmp])
        debs = sorted(tmp.glob("turtlegas_*.deb"))
        if len(debs) != 1:
            fail("cpack made {} (expected one turtlegas_*.deb)".format([p.name for p in tmp.iterdir()]))
        deb = debs[0]
        arch = run(["dpkg", "--print-architecture"]).stdout.strip()
        if deb.name != "turtlegas_{}_{}.deb".format(a.version, arch):
            fail("the package is called {}, expected turtlegas_{}_{}.deb".format(deb.name, a.version, arch))
        fields = {}
        for f in ["Package", "Version", "Architecture", "Depends", "Maintainer", "Description"]:
            fields[f] = run(["dpkg-deb", "-f", deb, f]).stdout.strip()
            if not fields[f]:
                fail("the package has no " + f + " field")
        if fields["Package"] != "turtlegas" or fields["Version"] != a.version or fields["Architecture"] != arch:
            fail("fields: " + repr(fields))
        depends = {re.split(r"[ (]", d.strip())[0] for d in fields["Depends"].split(",")}

        root = tmp / "root"
        run(["dpkg-deb", "-x", deb, root])
        turtlegas = root / "usr/bin/turtlegas"
        version = run([turtlegas, "--version"]).stdout
        if not version.startswith("turtlegas " + a.version + "\n"):
            fail("the unpacked turtlegas --version printed " + repr(version))
        worlds = root / "usr/share/turtlegas/worlds"
        demo = sorted(str(p) for p in worlds.glob("*.json"))
        if len(demo) < 10:
            fail("the package ships {} demo worlds".format(len(demo)))
        run([turtlegas, "check", *demo])
        run([turtlegas, "test", worlds / "tests/box_bounce.json", worlds / "tests/tag_it.json"])
        for rel in ["usr/include/turtlegas/turtle/turtle.hpp", "usr/share/doc/turtlegas/controllers.md",
                    "usr/share/turtlegas/examples/feeler/CMakeLists.txt"]:
            if not (root / rel).exists():
                fail("the package does not hold /" + rel)
        check_installed_viewer(turtlegas, root / "usr/share/turtlegas/web", worlds / "tag.json", fail)

        # The Python module, when the build made it: in Debian's system dist-packages.
        if list((a.build / "python/turtlegas").glob("_turtlegas*.so")):
            place = root / "usr/lib/python3/dist-packages"
            if not (place / "turtlegas/__init__.py").exists() or not list((place / "turtlegas").glob("_turtlegas*.so")):
                fail("the package does not hold the Python module in /usr/lib/python3/dist-packages/turtlegas")
            script = ("import turtlegas, turtlegas.client, sys; w = turtlegas.World.load(sys.argv[1]); w.run(0.5); "
                      "assert turtlegas.__file__.startswith(sys.argv[2]); print('ok')")
            r = run([sys.executable, "-c", script, worlds / "gas.json", place], env=dict(os.environ, PYTHONPATH=str(place)))
            if r.stdout.strip() != "ok":
                fail("the packaged Python module printed " + repr(r.stdout))

        if not list(root.glob("usr/lib*/**/cmake/turtlegas/turtlegasConfig.cmake")):
            fail("the package does not hold the CMake package (usr/lib/.../cmake/turtlegas)")

        # Depends against what the program needs.
        needed = re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", run(["readelf", "-d", turtlegas]).stdout)
        resolved = dict(re.findall(r"^\s*(\S+) => (\S+)", run(["ldd", turtlegas]).stdout, re.M))
        missing = []
        for lib in needed:
            if lib not in resolved:
                fail("the loader does not find {} for the unpacked program (ldd)".format(lib))
            pkgs = owners(resolved[lib])
            if not pkgs:
                fail("no Debian package owns {} ({})".format(lib, resolved[lib]))
            # A Depends may name a virtual package the owner provides (libspdlog1.10 provides
            # libspdlog1.10-fmt9, the name its shlibs file gives).
            names = set(pkgs)
            for p in pkgs:
                provides = run(["dpkg-query", "-W", "-f=${Provides}", p], ok=(0, 1)).stdout
                names |= {re.split(r"[ (]", x.strip())[0] for x in provides.split(",") if x.strip()}
            if not names & depends:
                missing.append("{} (from {})".format(lib, ", ".join(sorted(pkgs))))
        if missing:
            fail("Depends ({}) lacks the package of: {}".format(fields["Depends"], "; ".join(missing)))
        # The SDK's registry.hpp includes <nlohmann/json.hpp>: a dependency, not a suggestion.
        if "nlohmann-json3-dev" not in depends:
            fail("Depends ({}) lacks nlohmann-json3-dev, which the SDK's headers include".format(fields["Depends"]))
        if not list(root.glob("usr/lib/cmake/turtlegas/turtlegasConfig.cmake")):
            fail("the CMake package is not where docs/controllers.md says (usr/lib/cmake/turtlegas)")

        apt = ""
        if shutil.which("apt-get"):
            r = run(["apt-get", "install", "--simulate", "--no-install-recommends", str(deb)], ok=(0, 100))
            if r.returncode != 0 or not re.search(r"^Inst turtlegas ", r.stdout, re.M):
                fail("apt-get install --simulate ./{} does not install it:\n{}{}".format(deb.name, r.stdout[-2000:],
                                                                                       r.stderr[-2000:]))
            apt = "; apt-get install --simulate accepts it"
        print("deb_test: ok: {} unpacked and ran; Depends: {}{}".format(deb.name, fields["Depends"], apt))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
