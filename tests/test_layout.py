"""The package's layout: no import cycle, and no stage importing a later one, so that the
folder tree reads as the pipeline (README.md, "Layout").

Imports are read from the source with ``ast`` (lazy imports inside functions count: a lazy
import still makes a cycle, it only hides it)."""

import ast
from pathlib import Path

import masonry

ROOT = Path(masonry.__file__).parent

# the pipeline's order: a module may import only from its own stage or earlier ones
STAGES = (
    ("masonry.errors", "masonry.parameters", "masonry.tolerances", "masonry.optional",
     "masonry.friction", "masonry.contact", "masonry.mortars", "masonry.outputs",
     "masonry.runfolder", "masonry.forking", "masonry.cleaning"),
    ("masonry.blocks", "masonry.meshing"),
    ("masonry.dome",),
    ("masonry.scenes",),
    ("masonry.interfaces",),
    ("masonry.rbe",),
    ("masonry.params", "masonry.assembly"),
    ("masonry.printable", "masonry.plots"),
    ("masonry.export",),
    ("masonry.cache", "masonry.pipeline"),
    ("masonry.stages",),
    ("masonry.studies",),
    # the package's __init__ hands out the Python interface (imported when first used)
    ("masonry.api", "masonry"),
    # adapters that let other tools call masonry (imported only by their users)
    ("masonry.interop",),
)


def module_names():
    names = {}
    for path in ROOT.rglob("*.py"):
        parts = ("masonry",) + path.relative_to(ROOT).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        names[name] = path
    return names


def imports(name, path, known):
    """Modules of ``known`` that ``name`` imports (a package import counts as its
    ``__init__``; ``from package import module`` as the module)."""
    package = name if path.stem == "__init__" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            candidates = [target] + [f"{target}.{alias.name}" for alias in node.names]
        elif isinstance(node, ast.Import):
            candidates = [alias.name for alias in node.names]
        else:
            continue
        found.update(c for c in candidates if c in known and c != name
                     and not name.startswith(c + "."))
    return found


def stage_of(name):
    for rank, prefixes in enumerate(STAGES):
        if any(name == p or (p != "masonry" and name.startswith(p + ".")) for p in prefixes):
            return rank
    raise AssertionError(f"{name} is in no stage of the layout: add it to STAGES")


def graph():
    names = module_names()
    return {name: imports(name, path, names) for name, path in names.items()}


def test_every_module_has_a_stage():
    for name in module_names():
        stage_of(name)


def test_no_stage_imports_a_later_one():
    later = [f"{a} -> {b}" for a, targets in graph().items() for b in targets
             if stage_of(b) > stage_of(a)]
    assert later == []


def test_no_import_cycle():
    edges = graph()
    state, cycles = {}, []

    def visit(node, path):
        state[node] = "open"
        for nxt in sorted(edges[node]):
            if state.get(nxt) == "open":
                cycles.append(" -> ".join(path[path.index(nxt):] + [nxt]))
            elif nxt not in state:
                visit(nxt, path + [nxt])
        state[node] = "done"

    for node in sorted(edges):
        if node not in state:
            visit(node, [node])
    assert cycles == []


def test_the_checker_sees_a_cycle(tmp_path):
    """The parser finds lazy and relative imports (so the tests above can fail)."""
    a = tmp_path / "a.py"
    a.write_text("def f():\n    from .b import g\n")
    assert imports("masonry.x.a", a, {"masonry.x.b"}) == {"masonry.x.b"}
