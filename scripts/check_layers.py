#!/usr/bin/env python3
"""The house's layering, checked against the build (docs/architecture.md).

Usage: check_layers.py MODULE_GRAPH SOURCE_DIR

MODULE_GRAPH is the build's module_graph.txt (cmake/BimsHelpers.cmake,
bims_write_module_graph): "module: the modules it links directly". Two
checks, each failure printed with the file or the link that breaks it:

1. Every #include <bims/X/...> in a library's include/ and src/ names the
   library itself or a module it links, directly or through others: a header
   of a module that is not linked compiles today by accident of the include
   paths and breaks the one-way order tomorrow.
2. The house rules on the links themselves (RULES below): e.g. the frame
   source reads recordings with the sensor rig's sections and never links the
   egomotion.

Exit status: 0 when both hold, 1 otherwise, 2 on bad usage.
"""
import pathlib
import re
import sys

# (module, modules it must not reach, directly or through others ("*": any;
# None: see ONLY), why)
RULES = [
    ("common", {"*"}, "the base of every module links no other"),
    ("sensors", None, "the sensor rig sits on common alone"),
    ("io", None, "the files sit on common alone"),
    ("source", {"ego", "flow", "maps", "maps_core", "pipeline", "apps"},
     "the frame source needs the sensor rig's sections, not the egomotion"),
    ("ego", {"source", "flow", "maps", "maps_core", "pipeline", "apps"},
     "the egomotion knows no stage after it"),
    ("maps_core", {"ego", "flow", "source", "pipeline", "apps"},
     "the grids know no other stage"),
    ("flow", {"ego", "maps", "maps_core", "source", "pipeline", "apps"},
     "the flow tier knows no other stage"),
    ("pipeline", {"apps", "eval", "viewer", "sweep"},
     "the pipeline knows no program"),
]
ONLY = {"sensors": {"common"}, "io": {"common"}}  # may reach these alone

# the include folder a module's headers live in, when not its own name
INCLUDE_DIR = {"maps_core": "maps"}
# the module whose code a libs/ folder holds, when not the folder's name
FOLDER_MODULE = {"maps": "maps_core"}


def read_graph(path):
    graph = {}
    for line in pathlib.Path(path).read_text().splitlines():
        if not line.strip():
            continue
        name, _, deps = line.partition(":")
        graph[name.strip()] = deps.split()
    return graph


def closure(graph, module):
    seen, todo = set(), list(graph.get(module, []))
    while todo:
        m = todo.pop()
        if m in seen:
            continue
        seen.add(m)
        todo.extend(graph.get(m, []))
    return seen


def main(argv):
    if len(argv) != 3:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    graph = read_graph(argv[1])
    src = pathlib.Path(argv[2])
    if not graph:
        print(f"check_layers: {argv[1]}: no modules", file=sys.stderr)
        return 2
    problems = []

    include_re = re.compile(r"^\s*#\s*include\s*<bims/([a-z_]+)/", re.M)
    for module in sorted(graph):
        folder = next((f for f, m in FOLDER_MODULE.items() if m == module),
                      module)
        if FOLDER_MODULE.get(module) is not None:
            continue  # the folder's code belongs to another target
        root = src / "libs" / folder
        reach = {INCLUDE_DIR.get(m, m) for m in closure(graph, module)}
        reach.add(INCLUDE_DIR.get(module, module))
        files = [p for d in ("include", "src") if (root / d).is_dir()
                 for p in sorted((root / d).rglob("*"))
                 if p.suffix in (".h", ".hpp", ".cpp")]
        for f in files:
            for m in include_re.finditer(f.read_text(errors="replace")):
                if m.group(1) not in reach:
                    line = f.read_text(errors="replace")[:m.start()].count(
                        "\n") + 1
                    problems.append(
                        f"{f.relative_to(src)}:{line}: includes bims/"
                        f"{m.group(1)}/ but {module} does not link "
                        f"{m.group(1)} (links: "
                        f"{' '.join(sorted(closure(graph, module))) or '-'})")

    for module, banned, why in RULES:
        if module not in graph:
            continue
        reached = closure(graph, module)
        bad = set()
        if module in ONLY:
            bad = reached - ONLY[module]
        elif banned and "*" in banned:
            bad = reached
        elif banned:
            bad = reached & banned
        for b in sorted(bad):
            problems.append(f"module {module} reaches {b}: {why}")

    for p in problems:
        print(p)
    print(f"check_layers: {len(graph)} modules, {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
