"""The README's Python example runs as written and prints what the README says it prints,
and every relative link of the README and of docs/ leads to a file and heading that
exist."""

import math
import re
from pathlib import Path

import pandas

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
VERDICTS = ("feasible", "infeasible", "not solved")


def first_block(text: str, language: str) -> str:
    """The first fenced code block of ``language`` in a Markdown text."""
    match = re.search(rf"^```{language}\n(.*?)^```$", text, flags=re.MULTILINE | re.DOTALL)
    assert match, f"README.md has no ```{language} block"
    return match.group(1)


def test_the_python_example_runs(tmp_path, monkeypatch, capsys):
    """The first ```python block, executed in a fresh folder (its export writes there);
    the ```text block after it shows its output: the verdict and the collapse load factor
    lines must be printed as shown."""
    text = README.read_text(encoding="utf-8")
    code = first_block(text, "python")
    monkeypatch.chdir(tmp_path)
    names = {"__name__": "__readme__"}
    exec(compile(code, str(README), "exec"), names)  # noqa: S102 (the README's own code)
    printed = capsys.readouterr().out

    dome, result, forces, collapse, record = (names[k] for k in (
        "dome", "result", "forces", "collapse", "record"))
    assert result.verdict in VERDICTS
    assert isinstance(forces, pandas.DataFrame) and len(forces) == len(dome.interfaces)
    assert math.isfinite(collapse.load_factor) and collapse.load_factor > 0
    folder = Path(record["path"])
    if not folder.is_absolute():
        folder = tmp_path / folder
    assert folder.resolve().is_relative_to(tmp_path.resolve())
    assert (folder / "run.json").is_file() and (folder / "RBE" / "forces.csv").is_file()

    shown = first_block(text[text.index(code):], "text").splitlines()
    for line in (shown[0], next(s for s in shown if s.startswith("collapse load factor"))):
        assert line in printed.splitlines(), f"README shows {line!r}; printed:\n{printed}"


def without_code(text: str) -> str:
    """A Markdown text without its fenced code blocks."""
    return re.sub(r"^```.*?^```$", "", text, flags=re.MULTILINE | re.DOTALL)


def slug(heading: str) -> str:
    """GitHub's anchor of a Markdown heading."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


def anchors(path: Path) -> set:
    """The anchors of a Markdown file: its headings' (repeats numbered as GitHub does) and
    explicit ``<a id="...">`` ones."""
    found, seen = set(), {}
    text = without_code(path.read_text(encoding="utf-8"))
    for heading in re.findall(r"^#{1,6} (.+)$", text, flags=re.MULTILINE):
        name = slug(heading)
        found.add(f"{name}-{seen[name]}" if name in seen else name)
        seen[name] = seen.get(name, 0) + 1
    found.update(re.findall(r'<a id="([^"]+)">', text))
    return found


def test_links_resolve():
    """Every relative link ``[text](target)`` of README.md and docs/*.md names a file
    that exists and, with ``#anchor``, a heading or anchor in it."""
    broken = []
    for page in [README, *sorted((ROOT / "docs").glob("*.md"))]:
        text = without_code(page.read_text(encoding="utf-8"))
        for target in re.findall(r"\]\(([^)\s]+)\)", text):
            if re.match(r"[a-z]+:", target):
                continue
            file, _, anchor = target.partition("#")
            path = (page.parent / file).resolve() if file else page
            if not path.exists():
                broken.append(f"{page.name}: {target} (no such file)")
            elif anchor and path.suffix == ".md" and anchor not in anchors(path):
                broken.append(f"{page.name}: {target} (no such heading)")
    assert not broken, "\n".join(broken)
