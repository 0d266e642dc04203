#!/usr/bin/env python3
"""The module graph check: every #include of a project header must come from the including
target's own headers or from a target it declares in CMake (PUBLIC, PRIVATE or INTERFACE; in a
header, PUBLIC or INTERFACE only, as its users see no more; tests may also use what those bring
along publicly), the
graph must have no cycle, and the rooms must not lean on each other (recognition and tables know
nothing of hal/, firmware/, tools/ or tests/; hal/ knows nothing of firmware/, tools/ or tests/;
the board's code nothing of the simulated world), the firmware and the recognise command
include no recognition path's own header (they use the facade, recog/pipeline/object_recognizer),
and tables/ sits below recognition: its formats and readers use only recognition's foundation
(recog/base, recog/model), which knows nothing of tables/, so that recog/ and tables/ never lean
on each other; the builders that need the algorithms are in tools/tablegen, above both. Reads
the manifest CMake writes (build/<preset>/module_graph.txt).

  tools/check_includes.py MANIFEST            check; exit 1 with one line per problem
  tools/check_includes.py MANIFEST --graph    print the module graph (direct declared deps)
"""
import os
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)

# (directory prefix of a target's files, directory prefixes it must never depend on).
ROOMS = [
    ("recog/", ("hal/", "firmware/", "tools/", "tests/")),
    ("tables/", ("hal/", "firmware/", "tools/", "tests/")),
    ("hal/", ("firmware/", "tools/", "tests/")),
    ("firmware/", ("tools/", "tests/")),
    ("tools/eval/", ("tests/",)),
]
# Targets of the board program: nothing of the simulated world or the simulator backends reaches
# them. The one exception is the image files module (PNG on libpng, PGM): the board writes its
# recordings (firmware/recorder, record_dir) with it.
BOARD_FORBIDDEN = ("hal/sim/",)
BOARD_ALLOWED = ("stereohash_image_files",)
# One recognition facade (recog/pipeline/object_recognizer.hpp) owns every path: the firmware
# and the recognise command reach the paths through it and include none of a path's own headers.
FACADE_USERS = ("firmware/", "tools/cmd_recognize.cpp")
PATH_HEADERS = re.compile(r"^recog/(texture|shape|mono|hashing|stereo|verify)/")
# The readers in tables/ (what the board links of the model data) stand on recognition's
# foundation only: these targets, which in turn depend on nothing in tables/.
READERS = "tables/"
FOUNDATION = ("stereohash_base", "stereohash_model")


def parse_manifest(path):
    """Lines: `target|kind|file;file;...|dep;dep;...|public;...` (files relative to the root)."""
    targets = {}
    root = None
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.rstrip("\n")
            if line.startswith("root|"):
                root = line.split("|", 1)[1]
                continue
            if not line or line.startswith("#"):
                continue
            name, kind, files, deps, public = line.split("|")
            targets[name] = {
                "kind": kind,
                "files": [x for x in files.split(";") if x],
                "deps": [x for x in deps.split(";") if x],
                "public": [x for x in public.split(";") if x],
            }
    return root, targets


def in_dir(targets, name, prefix):
    files = targets[name]["files"]
    return bool(files) and all(f.startswith(prefix) for f in files)


def reader_problems(root, targets, owner):
    """tables/ below recognition: its targets depend on tables/ and the foundation only, its files
    include no other recog/ header, and the foundation depends on nothing in tables/."""
    problems = []
    for name, t in targets.items():
        if t["kind"] == "test":
            continue
        if in_dir(targets, name, READERS):
            for d in t["deps"]:
                if d in targets and not in_dir(targets, d, READERS) and d not in FOUNDATION:
                    problems.append(f"{name} (a reader in {READERS}) depends on {d}, which is "
                                    "neither a reader nor recognition's foundation")
            for f in t["files"]:
                path = os.path.join(root, f)
                if not os.path.isfile(path):
                    continue
                with open(path, encoding="utf-8", errors="replace") as src:
                    for inc in INCLUDE.findall(src.read()):
                        o = owner.get(inc)
                        if inc.startswith("recog/") and o not in FOUNDATION:
                            problems.append(f"{f}: includes {inc} ({o}): {READERS} sits below "
                                            "recognition and includes only its foundation")
        if name in FOUNDATION:
            for d in t["deps"]:
                if d in targets and in_dir(targets, d, READERS):
                    problems.append(f"{name} (recognition's foundation) depends on {d} "
                                    f"({READERS})")
    return problems


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    root, targets = parse_manifest(sys.argv[1])
    owner = {}
    problems = []
    for name, t in targets.items():
        for f in t["files"]:
            if f.endswith((".hpp", ".h")):
                if f in owner and owner[f] != name:
                    problems.append(f"{f}: listed by both {owner[f]} and {name}")
                owner[f] = name

    if "--graph" in sys.argv:
        for name in sorted(targets):
            t = targets[name]
            if t["kind"] == "test":
                continue
            deps = sorted(d for d in t["deps"] if d in targets)
            print(f"{name} -> {', '.join(deps) if deps else '(nothing)'}")
        return 0

    def closure(name, key="deps"):
        seen, todo = set(), [name]
        while todo:
            for d in targets[todo.pop()][key]:
                if d in targets and d not in seen:
                    seen.add(d)
                    todo.append(d)
        return seen

    def visible(name):  # what the compiler lets a target include: its deps and their public ones
        seen = set()
        for d in targets[name]["deps"]:
            if d in targets:
                seen |= {d} | closure(d, "public")
        return seen

    # Includes against declared deps: direct ones for the project's own targets; tests may use
    # whatever the targets they link bring along.
    for name, t in targets.items():
        allowed_sources = {name} | (visible(name) if t["kind"] == "test" else set(t["deps"]))
        # A target's headers are read by its users, who see only its public dependencies.
        allowed_headers = {name} | set(t["public"]) if t["kind"] == "module" else allowed_sources
        for f in t["files"]:
            allowed = allowed_headers if f.endswith((".hpp", ".h")) else allowed_sources
            path = os.path.join(root, f)
            if not os.path.isfile(path):
                problems.append(f"{f}: listed by {name} but missing")
                continue
            with open(path, encoding="utf-8", errors="replace") as src:
                text = src.read()
            for inc in INCLUDE.findall(text):
                if not os.path.isfile(os.path.join(root, inc)):
                    continue  # not a project header (generated, third-party, relative)
                o = owner.get(inc)
                if o is None:
                    problems.append(f"{f}: includes {inc}, which no target lists")
                elif o not in allowed:
                    how = "publicly " if allowed is allowed_headers and o in t["deps"] else ""
                    problems.append(
                        f"{f}: includes {inc} ({o}), which {name} does not declare {how}".rstrip())

    # The facade's users.
    for t in targets.values():
        for f in t["files"]:
            if not f.startswith(FACADE_USERS) or not os.path.isfile(os.path.join(root, f)):
                continue
            with open(os.path.join(root, f), encoding="utf-8", errors="replace") as src:
                for inc in INCLUDE.findall(src.read()):
                    if PATH_HEADERS.match(inc):
                        problems.append(f"{f}: includes {inc}, a recognition path's own header "
                                        "(use recog/pipeline/object_recognizer.hpp)")

    problems += reader_problems(root, targets, owner)

    # Cycles among declared deps.
    state = {}

    def visit(n, stack):
        state[n] = 1
        for d in targets[n]["deps"]:
            if d not in targets:
                continue
            if state.get(d) == 1:
                cycle = stack[stack.index(d):] + [d] if d in stack else [n, d]
                problems.append("cycle: " + " -> ".join(cycle))
            elif d not in state:
                visit(d, stack + [d])
        state[n] = 2

    for n in targets:
        if n not in state:
            visit(n, [n])

    # Rooms.
    def dirs_of(name):
        return {os.path.dirname(f) + "/" for f in targets[name]["files"]}

    for name, t in targets.items():
        if t["kind"] == "test":
            continue
        mine = dirs_of(name)
        for d in t["deps"]:
            if d not in targets:
                continue
            theirs = dirs_of(d)
            for prefix, banned in ROOMS:
                if any(m.startswith(prefix) for m in mine):
                    for b in banned:
                        if any(x.startswith(b) for x in theirs):
                            problems.append(f"{name} ({prefix}) depends on {d} ({b})")
        if t["kind"] == "board":
            for d in sorted(closure(name)):
                if d in BOARD_ALLOWED:
                    continue
                if any(x.startswith(BOARD_FORBIDDEN) for x in dirs_of(d)):
                    problems.append(f"board program {name} links {d} (simulator code)")

    for p in problems:
        print(p)
    checked = sum(len(t["files"]) for t in targets.values())
    print(f"module graph: {len(targets)} targets, {checked} files, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
