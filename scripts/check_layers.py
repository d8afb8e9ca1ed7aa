#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The house's include rules, checked from the sources (python3 standard library only).

Reads every `#include "..."` in the layer folders, resolves it to a file of the tree and fails on:
  - an include that runs upward (a file including a file of a higher layer) or sideways (between
    two folders of the same layer, which are meant to stay independent);
  - an include loop between files (any cycle in the file graph, headers or sources);
  - an include that resolves to no file, or to several (so nothing passes by not being seen);
  - a third-party header where the house forbids it (sim/ uses the standard library only;
    Boost.Context is included by turtle_runtime/src/fiber.cpp alone);
  - a controller (or controller plugin) that includes more of the runtime than the controller API
    (turtle.hpp) and the registry (registry.hpp).

The layer table below is the one place the layers are written down (docs/architecture.md explains
it). Usage:
  scripts/check_layers.py [--root DIR] [--verbose]   check a tree (default: this repository)
  scripts/check_layers.py --self-test                 check the checker on small fake trees
Exit code 0 when the tree keeps the rules, 1 when it does not, 2 for bad usage.
"""

import argparse
import os
import re
import sys
import tempfile

# Folder -> layer. A file may include files of its own folder and of folders of a lower layer.
# Folders that share a layer are siblings and may not include each other.
LAYERS = {
    "sim": 1,             # geometry, times of impact, the engine; the C++ standard library only
    "turtle_runtime": 2,  # fibers, agents, the scheduler, sensors, the registry
    "controllers": 3,     # controller programs, compiled against the controller API only
    "world_files": 4,     # reading world files: loader, gas, draw, expect, games, tournaments
    "formats": 4,         # the output contracts: event log, state file, stats, SVG
    "server": 5,          # the network world server (on runtime, world_files and formats)
    "learn": 5,           # vectorised worlds for learning: VecWorld (on the engine and world_files)
    "apps": 6,            # the programs (the turtlegas CLI)
    "python": 6,          # the Python module (pybind11), beside the programs
    "bench": 7,           # benchmarks and tests see everything, private headers included
    "tests": 7,
    "fuzz": 7,            # the libFuzzer harnesses, like the tests
}

# What a controller may include from the layers below it: the controller API and the registry.
API_ONLY = ("controllers/", "tests/cli/test_plugin.cpp")
API_HEADERS = {"turtle_runtime/include/turtlegas/turtle/turtle.hpp",
               "turtle_runtime/include/turtlegas/turtle/registry.hpp"}

# Third-party headers (angle brackets with a path) and where they may appear.
SIM_STD_ONLY = "sim/"  # in sim/, any <a/b> or <x.h>/<x.hpp> include is a third-party one
BOOST_CONTEXT = ("boost/context/", {"turtle_runtime/src/fiber.cpp"})
# The system headers sim/ may include, each in one file and for one reason (no I/O, no threads).
SIM_SYSTEM = {("sim/src/engine/big_memory.cpp", "sys/mman.h"):
              "madvise(MADV_HUGEPAGE), a memory hint for the large arrays of a big gas"}

# Loops between units (a header and its .cpp) that are known and owned by work in progress, each as
# (folder every file of the loop lies in, a file the loop passes through, why and who ends it).
# Only units count here: a loop of files would not compile, and is never excused.
# (folder, a file of the loop, why): loops that are understood and allowed; none today
KNOWN_LOOPS = []

SOURCE_EXTENSIONS = (".cpp", ".hpp", ".h", ".cc", ".ipp")
SKIP_DIRS = {".git", "build", "node_modules", "__pycache__"}

INCLUDE_RE = re.compile(r'^\s*#\s*include\s*([<"])([^">]+)[">]')


def layer_of(path):
    """The top folder of a repository-relative path, if it is a layer folder."""
    top = path.split("/", 1)[0]
    return top if top in LAYERS else None


def scan(root):
    """Every source file under the layer folders, as repository-relative paths."""
    files = []
    for top in sorted(LAYERS):
        base = os.path.join(root, top)
        if not os.path.isdir(base):
            continue
        for dirpath, dirnames, filenames in os.walk(base):
            dirnames[:] = sorted(d for d in dirnames if d not in SKIP_DIRS and not d.startswith("build"))
            for name in sorted(filenames):
                if name.endswith(SOURCE_EXTENSIONS):
                    files.append(os.path.relpath(os.path.join(dirpath, name), root).replace(os.sep, "/"))
    return files


def read_includes(root, path):
    """(line number, '<' or '"', target) for each #include outside comments."""
    out = []
    in_block = False
    with open(os.path.join(root, path), encoding="utf-8", errors="replace") as f:
        for number, line in enumerate(f, 1):
            stripped = line.strip()
            if in_block:
                if "*/" in stripped:
                    in_block = False
                continue
            if stripped.startswith("/*") and "*/" not in stripped:
                in_block = True
                continue
            m = INCLUDE_RE.match(line)
            if m:
                out.append((number, m.group(1), m.group(2)))
    return out


class Resolver:
    """Maps an include's text to a file of the tree, as the build's include paths would."""

    def __init__(self, files):
        self.files = set(files)
        self.public = {}  # "turtlegas/x/y.hpp" -> file, from every <folder>/.../include/ directory
        self.by_name = {}  # basename -> files, for private headers reached through an include path
        for f in files:
            parts = f.split("/")
            if "include" in parts:
                k = parts.index("include")
                self.public.setdefault("/".join(parts[k + 1:]), []).append(f)
            self.by_name.setdefault(parts[-1], []).append(f)

    def resolve(self, including, target):
        """(file, None) or (None, why)."""
        here = os.path.dirname(including)
        local = os.path.normpath(os.path.join(here, target)).replace(os.sep, "/")
        if local in self.files:
            return local, None
        if target in self.public:
            hits = self.public[target]
            if len(hits) == 1:
                return hits[0], None
            return None, "ambiguous: " + ", ".join(sorted(hits))
        # A private header on an include path (a folder's src/, say): found by its path's tail,
        # preferring the including file's own folder.
        tail = "/" + target
        hits = [f for f in self.by_name.get(os.path.basename(target), []) if ("/" + f).endswith(tail)]
        if len(hits) > 1:
            top = including.split("/", 1)[0]
            own = [f for f in hits if f.startswith(top + "/")]
            hits = own if own else hits
        if len(hits) == 1:
            return hits[0], None
        if not hits:
            return None, "no such file in the tree"
        return None, "ambiguous: " + ", ".join(sorted(hits))


def find_cycles(graph):
    """The include loops: per strongly connected component with more than one file (or a file that
    includes itself), one cycle through it (files, the first repeated last) and the component's
    other files (Tarjan's algorithm, iteratively)."""
    index, low, on_stack, stack, sccs = {}, {}, set(), [], []
    counter = 0
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            advanced = False
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.get(child, ())))))
                    advanced = True
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1 or node in graph.get(node, ()):
                    sccs.append(sorted(component))
    cycles = []
    for component in sccs:
        members = set(component)
        # A shortest way back to the component's first file, for the message.
        first = component[0]
        previous = {first: None}
        queue = [first]
        found = None
        while queue and found is None:
            node = queue.pop(0)
            for child in sorted(graph.get(node, ())):
                if child == first:
                    found = node
                    break
                if child in members and child not in previous:
                    previous[child] = node
                    queue.append(child)
        path = [first]
        node = found
        while node is not None and node != first:
            path.append(node)
            node = previous[node]
        cycle = [first] + list(reversed(path[1:])) + [first]
        others = [f for f in component if f not in cycle]
        cycles.append((cycle, others))
    return cycles


def check(root, verbose=False, known_loops=None):
    """The rule breaks of the tree at root, and a one-line summary."""
    known_loops = KNOWN_LOOPS if known_loops is None else known_loops
    files = scan(root)
    resolver = Resolver(files)
    problems = []
    graph = {f: set() for f in files}
    edges = 0
    for f in files:
        layer = layer_of(f)
        for number, kind, target in read_includes(root, f):
            where = "%s:%d" % (f, number)
            if kind == "<":
                if f.startswith(SIM_STD_ONLY) and ("/" in target or target.endswith((".h", ".hpp"))) \
                        and (f, target) not in SIM_SYSTEM:
                    problems.append("%s: <%s>: sim/ uses the C++ standard library only" % (where, target))
                if target.startswith(BOOST_CONTEXT[0]) and f not in BOOST_CONTEXT[1]:
                    problems.append("%s: <%s>: Boost.Context belongs to %s alone" %
                                    (where, target, ", ".join(sorted(BOOST_CONTEXT[1]))))
                continue
            dep, why = resolver.resolve(f, target)
            if dep is None:
                problems.append('%s: "%s": %s' % (where, target, why))
                continue
            graph[f].add(dep)
            edges += 1
            dep_layer = layer_of(dep)
            if dep_layer == layer:
                continue
            if LAYERS[dep_layer] > LAYERS[layer]:
                problems.append('%s: "%s": upward include, layer %d (%s/) includes layer %d (%s/)' %
                                (where, target, LAYERS[layer], layer, LAYERS[dep_layer], dep_layer))
            elif LAYERS[dep_layer] == LAYERS[layer]:
                problems.append('%s: "%s": %s/ and %s/ share layer %d and may not include each other' %
                                (where, target, layer, dep_layer, LAYERS[layer]))
            elif f.startswith(API_ONLY) and dep_layer != "sim" and dep not in API_HEADERS:
                problems.append('%s: "%s": a controller includes the controller API only (%s)' %
                                (where, target, ", ".join(sorted(os.path.basename(h) for h in API_HEADERS))))
            if verbose:
                print("  %s -> %s" % (f, dep))
    def loop_text(cycle, others):
        return " -> ".join(cycle) + ("" if not others else " (its other files: " + ", ".join(others) + ")")

    file_loops = set()
    for cycle, others in find_cycles(graph):
        file_loops.add(tuple(cycle))
        problems.append("include loop: " + loop_text(cycle, others))
    # A header and the source file that implements it (foo.cpp including .../foo.hpp) are one
    # unit: a loop through them is a loop of the design even when no file includes itself, e.g.
    # world_file.hpp -> expect.hpp while expect.cpp -> world_file.hpp (two rooms' interfaces).
    unit = {f: f for f in files}
    for f in files:
        if f.endswith((".cpp", ".cc")):
            stem = os.path.splitext(os.path.basename(f))[0]
            for dep in graph[f]:
                if dep.endswith((".hpp", ".h")) and os.path.splitext(os.path.basename(dep))[0] == stem:
                    unit[f] = dep
    units = {}
    for f in files:
        units.setdefault(unit[f], set()).update(unit[d] for d in graph[f] if unit[d] != unit[f])
    notes = []
    for cycle, others in find_cycles(units):
        if tuple(cycle) in file_loops:
            continue
        # A loop through one public header only is a room's own implementation seeing its interface
        # (world_server.cpp -> agent.hpp -> world_server.hpp, a pimpl's private parts): not a loop
        # between rooms. Two public headers that need each other are.
        if sum(1 for f in set(cycle + others) if "/include/" in f) < 2:
            continue
        text = loop_text(cycle, others)
        known = [why for (inside, through, why) in known_loops
                 if all(f.startswith(inside) for f in cycle + others) and through in cycle + others]
        if known:
            notes.append("known loop, not counted: %s (%s)" % (text, known[0]))
        else:
            problems.append("include loop (a header and its .cpp as one): " + text)
    folders = sorted({layer_of(f) for f in files})
    summary = "%d files in %d folders (%s), %d includes" % (len(files), len(folders), " ".join(folders), edges)
    return problems, notes, summary


def write_tree(root, files):
    for path, text in files.items():
        full = os.path.join(root, path)
        os.makedirs(os.path.dirname(full), exist_ok=True)
        with open(full, "w", encoding="utf-8") as f:
            f.write(text)


def self_test():
    """The checker on fake trees: a clean one passes; each kind of break is caught."""
    clean = {
        "sim/include/turtlegas/sim/vec2.hpp": "#pragma once\n#include <cmath>\n",
        "sim/src/world.cpp": '#include "turtlegas/sim/vec2.hpp"\n#include "cell_grid.hpp"\n',
        "sim/src/cell_grid.hpp": '#pragma once\n#include "turtlegas/sim/vec2.hpp"\n',
        "turtle_runtime/include/turtlegas/turtle/turtle.hpp": '#include "turtlegas/sim/vec2.hpp"\n',
        "turtle_runtime/include/turtlegas/turtle/registry.hpp": '#include "turtlegas/turtle/turtle.hpp"\n',
        "turtle_runtime/src/fiber.cpp": "#include <boost/context/fiber.hpp>\n",
        "controllers/wander.cpp": '#include "turtlegas/turtle/turtle.hpp"\n',
        "apps/turtlegas/main.cpp": '#include "turtlegas/turtle/registry.hpp"\n// #include "nowhere.hpp"\n',
        "tests/runtime/fiber_test.cpp": '#include "fiber.hpp"\n',
        "turtle_runtime/src/fiber.hpp": "#pragma once\n",
        # a pimpl: the implementation's private header sees the public one (not a loop of rooms)
        "turtle_runtime/include/turtlegas/turtle/world_server.hpp": '#include "turtlegas/turtle/turtle.hpp"\n',
        "turtle_runtime/src/agent.hpp": '#include "turtlegas/turtle/world_server.hpp"\n',
        "turtle_runtime/src/world_server.cpp": '#include "turtlegas/turtle/world_server.hpp"\n#include "agent.hpp"\n',
    }
    broken = {
        # upward: layer 1 includes layer 2 (sim/src/world.cpp, below)
        # a loop of three files
        "turtle_runtime/src/a.hpp": '#include "b.hpp"\n',
        "turtle_runtime/src/b.hpp": '#include "c.hpp"\n',
        "turtle_runtime/src/c.hpp": '#include "a.hpp"\n',
        # sideways between siblings
        "formats/src/event_log.cpp": '#include "turtlegas/world/scene.hpp"\n',
        "world_files/include/turtlegas/world/scene.hpp": "#pragma once\n",
        # a controller reaching past the API
        "controllers/spiral.cpp": '#include "turtlegas/turtle/world_server.hpp"\n',
        # third-party headers where they do not belong
        "sim/src/toi.cpp": "#include <nlohmann/json.hpp>\n",
        "turtle_runtime/src/agent.cpp": "#include <boost/context/fiber.hpp>\n",
        # a file that is not there
        "apps/turtlegas/run.cpp": '#include "turtlegas/formats/nowhere.hpp"\n',
        # a loop through a header's implementation: world_file.hpp -> expect.hpp, expect.cpp ->
        # world_file.hpp (no file includes itself, but the two rooms need each other)
        "world_files/include/turtlegas/world/world_file.hpp": '#include "turtlegas/world/expect.hpp"\n',
        "world_files/include/turtlegas/world/expect.hpp": "#pragma once\n",
        "world_files/src/expect.cpp": '#include "turtlegas/world/expect.hpp"\n#include "turtlegas/world/world_file.hpp"\n',
        # a loop listed as known (the self-test's own list) is a note, not a problem
        "sim/include/turtlegas/sim/reference.hpp": '#include "turtlegas/sim/world.hpp"\n',
        "sim/include/turtlegas/sim/world.hpp": "#pragma once\n",
        "sim/src/world.cpp": '#include "turtlegas/turtle/turtle.hpp"\n#include "turtlegas/sim/world.hpp"\n'
                             '#include "turtlegas/sim/reference.hpp"\n',
    }
    expected = ["upward include", "include loop: turtle_runtime/src/a.hpp -> turtle_runtime/src/b.hpp -> "
                "turtle_runtime/src/c.hpp -> turtle_runtime/src/a.hpp", "share layer 4",
                "controller API only", "standard library only", "Boost.Context belongs to",
                "no such file in the tree", "include loop (a header and its .cpp as one): "
                "world_files/include/turtlegas/world/expect.hpp -> world_files/include/turtlegas/world/world_file.hpp"]
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        good = os.path.join(tmp, "good")
        write_tree(good, clean)
        problems, _, _ = check(good)
        if problems:
            failures.append("the clean tree failed: " + "; ".join(problems))
        bad = os.path.join(tmp, "bad")
        write_tree(bad, {**clean, **broken})
        test_loops = [("sim/", "sim/include/turtlegas/sim/reference.hpp", "a loop the self-test allows")]
        problems, notes, _ = check(bad, known_loops=test_loops)
        if not any("known loop, not counted: sim/include/turtlegas/sim/reference.hpp" in n for n in notes):
            failures.append("the known loop was not noted: " + "; ".join(notes))
        for want in expected:
            if not any(want in p for p in problems):
                failures.append("not caught: " + want + " (got: " + "; ".join(problems) + ")")
        if len(problems) != len(expected):
            failures.append("%d problems for %d breaks: %s" % (len(problems), len(expected), "; ".join(problems)))
        # A file including itself is a loop too.
        selfish = os.path.join(tmp, "selfish")
        write_tree(selfish, {**clean, "sim/src/cell_grid.hpp": '#include "cell_grid.hpp"\n'})
        problems, _, _ = check(selfish)
        if not any(p.startswith("include loop: sim/src/cell_grid.hpp -> sim/src/cell_grid.hpp") for p in problems):
            failures.append("a file that includes itself was not caught: " + "; ".join(problems))
    for f in failures:
        print("check_layers self-test: FAIL: " + f)
    if not failures:
        print("check_layers self-test: ok (a clean tree with a pimpl passes; an upward include, a loop of three files, a "
              "sideways include, a controller past the API, two misplaced third-party headers, a missing file, "
              "a loop through a header's .cpp and a file including itself are each caught; a known loop is noted)")
    return 1 if failures else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    parser.add_argument("--self-test", action="store_true", help="check the checker on fake trees")
    parser.add_argument("--verbose", action="store_true", help="print every resolved include across folders")
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    if not os.path.isdir(args.root):
        print("check_layers: no directory %s" % args.root, file=sys.stderr)
        return 2
    problems, notes, summary = check(args.root, args.verbose)
    for n in notes:
        print("check_layers: note: " + n)
    for p in problems:
        print("check_layers: " + p)
    if problems:
        print("check_layers: FAIL: %d problem%s; %s" % (len(problems), "" if len(problems) == 1 else "s", summary))
        return 1
    print("check_layers: ok: no upward or sideways include, no include loop; " + summary)
    return 0


if __name__ == "__main__":
    sys.exit(main())
