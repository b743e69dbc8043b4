"""The package's layers, read from its source: each layer imports only the layers below it
(systems <- analytic <- simulators <- comparisons <- reports <- api <- cli), the report computes
nothing of its own, and no system id is written anywhere outside `systems/`."""
import ast
import re
from pathlib import Path

import pytest

import mbfidelity
from mbfidelity.systems import all_systems

PACKAGE = Path(mbfidelity.__file__).parent
LAYERS = ("systems", "analytic", "simulators", "comparisons", "reports", "api", "cli")
#: what the report pages draw is computed upstream and saved: the report reads the saved
#: results (through comparisons' results folder) and the descriptions only
REPORTS_MAY_NOT_IMPORT = ("analytic", "simulators")


def _module_name(path: Path) -> list[str]:
    parts = ["mbfidelity", *path.relative_to(PACKAGE).with_suffix("").parts]
    return parts[:-1] if parts[-1] == "__init__" else parts


def _layer(module: list[str]) -> str | None:
    """The layer of a module of the package (None: the package root, e.g. __version__)."""
    if len(module) < 2:
        return None
    return module[1] if module[1] in LAYERS else None


def _imports(path: Path):
    """(line, imported module as parts) of every import in the file, at any depth,
    relative ones resolved."""
    own = _module_name(path)
    package = own if path.name == "__init__.py" else own[:-1]
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name.split(".")
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - node.level + 1]
            else:
                base = []
            target = base + (node.module.split(".") if node.module else [])
            if node.module is None:
                # `from . import x`: each name may itself be a module
                for alias in node.names:
                    yield node.lineno, target + [alias.name]
            else:
                yield node.lineno, target


def _sources():
    return sorted(PACKAGE.rglob("*.py"))


def test_sources_found():
    layers = {_layer(_module_name(p)) for p in _sources()}
    assert set(LAYERS) <= layers


@pytest.mark.parametrize("path", _sources(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_imports_run_down_the_layers(path):
    layer = _layer(_module_name(path))
    if layer is None:
        return
    upward = []
    for line, target in _imports(path):
        if target[0] != "mbfidelity":
            continue
        to = _layer(target)
        if to is not None and LAYERS.index(to) > LAYERS.index(layer):
            upward.append(f"line {line}: {layer} imports {'.'.join(target)} ({to})")
        if layer == "reports" and to in REPORTS_MAY_NOT_IMPORT:
            upward.append(f"line {line}: the report imports {'.'.join(target)}: it renders "
                          "saved results, the computation belongs in comparisons")
    assert not upward, "\n".join(upward)


def _string_literals(path: Path):
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            yield node.lineno, node.value


def test_no_system_id_outside_systems():
    """Adding a mechanism is one module in systems/: no table, closed form, note or
    docstring elsewhere names a system by its id."""
    ids = list(all_systems())
    pattern = re.compile(r"(?<![A-Za-z0-9_])(" + "|".join(map(re.escape, ids))
                         + r")(?![A-Za-z0-9_])")
    found = []
    for path in _sources():
        if _layer(_module_name(path)) == "systems":
            continue
        for line, text in _string_literals(path):
            for m in pattern.finditer(text):
                found.append(f"{path.relative_to(PACKAGE)}:{line}: {m.group(1)}")
    assert not found, "\n".join(found)


#: documents of the workplace that are not part of the repository: the repository cites
#: the monograph (by section, figure and equation) and the published sources, never these
OUTSIDE_DOCUMENTS = re.compile(r"MECHANISMS\.md|SIMULATORS\.md|BENCHMARKS\.md|DESIGN\.md"
                               r"|\.\./shared\b")


def test_the_repository_cites_nothing_outside_itself():
    root = PACKAGE.parent.parent
    texts = [p for folder in ("src", "tests", "docs", "benchmarks", "examples")
             for p in (root / folder).rglob("*") if p.suffix in (".py", ".md", ".txt", ".json")
             and "egg-info" not in str(p)]
    texts += [root / "README.md"]
    assert len(texts) > 50
    cited = [f"{p.relative_to(root)}:{i}" for p in texts if p.exists()
             for i, line in enumerate(p.read_text(errors="replace").splitlines(), 1)
             if OUTSIDE_DOCUMENTS.search(line) and p.name != "test_layers.py"]
    assert not cited, cited
