"""The documentation stays true: every relative link in README.md, docs/*.md and the examples'
READMEs resolves (the file, and a `#anchor` to a heading of a Markdown file), every file and
every name of the code they give in a code span exists, docs/model.md documents every effect the
registry has, no file points outside the repository, and every `nodeforce COMMAND` shown in a
code block is a command whose `--help` exists and lists each `--option` shown with it.

The pages are parsed, not listed here, so a page or command added to the docs is checked too.
"""
import io
import re
from contextlib import redirect_stderr, redirect_stdout
from functools import lru_cache
from pathlib import Path

import pytest

from nodeforce.cli import main

ROOT = Path(__file__).parents[1]
PAGES = [ROOT / "README.md", ROOT / "CHANGELOG.md", ROOT / "CONTRIBUTING.md", *sorted((ROOT / "docs").glob("*.md"))]
EXAMPLE_PAGES = sorted((ROOT / "examples").glob("*/README.md"))

FENCE = re.compile(r"^\s*(```|~~~)")
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
COMMAND = re.compile(r"(?:^|[\s/])nodeforce\s+([a-z][a-z-]*)")
OPTION = re.compile(r"(?<![\w-])(--[a-z][a-z0-9-]*)")


def code_blocks(text):
    """The code blocks of a Markdown text, each as a list of lines: fenced blocks, and indented
    ones (lines indented by four spaces or more after a blank line, or after another such line)."""
    blocks, block, fenced, previous_blank = [], None, False, True
    for line in text.splitlines():
        if FENCE.match(line):
            if fenced:
                blocks.append(block)
                block, fenced = None, False
            else:
                if block:
                    blocks.append(block)
                block, fenced = [], True
            previous_blank = False
            continue
        if fenced:
            block.append(line)
        elif line.startswith("    ") and line.strip() and (previous_blank or block is not None):
            block = (block or []) + [line]
        elif block is not None and line.strip():
            blocks.append(block)
            block = None
        previous_blank = not line.strip()
    if block:
        blocks.append(block)
    return blocks


def commands(block):
    """(command, [options]) for every `nodeforce COMMAND` in a code block, with the options on
    its line and on its continuation lines (after a trailing backslash, or indented lines
    starting with `[` or `-`, as in a synopsis). Shell comments are left out."""
    found = []
    lines = [re.sub(r"(^|\s)#.*", "", line) for line in block]
    for i, line in enumerate(lines):
        match = COMMAND.search(line)
        if not match:
            continue
        text, j = line[match.end():], i
        while j + 1 < len(lines) and (lines[j].rstrip().endswith("\\")
                                      or re.match(r"\s+[\[-]", lines[j + 1])):
            j += 1
            if COMMAND.search(lines[j]):
                break
            text += " " + lines[j]
        found.append((match.group(1), OPTION.findall(text)))
    return found


def slug(heading):
    """A heading's anchor as the forge makes it: lower case, punctuation but hyphens dropped,
    spaces as hyphens."""
    text = re.sub(r"[`*_]", "", heading.strip().lower())
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def anchors(page):
    text = page.read_text(encoding="utf-8")
    outside_code = re.sub(r"```.*?```", "", text, flags=re.S)
    return {slug(m.group(1)) for m in re.finditer(r"^#{1,6}\s+(.+?)\s*#*\s*$", outside_code, re.M)}


def links(page):
    text = re.sub(r"```.*?```", "", page.read_text(encoding="utf-8"), flags=re.S)
    text = re.sub(r"`[^`\n]*`", "", text)  # code spans are not links
    return [target for target in LINK.findall(text) if not re.match(r"[a-z][a-z0-9+.-]*:", target)]


@lru_cache(maxsize=None)
def help_text(command):
    """(exit status, output) of `nodeforce COMMAND --help`, run in this process."""
    out = io.StringIO()
    with redirect_stdout(out), redirect_stderr(out):
        try:
            main([command, "--help"])
            status = 0
        except SystemExit as e:
            status = e.code
    return status, out.getvalue()


def shown_commands():
    return sorted({(page.relative_to(ROOT).as_posix(), command, tuple(sorted(set(options))))
                   for page in PAGES for block in code_blocks(page.read_text(encoding="utf-8"))
                   for command, options in commands(block)})


def test_the_parser_finds_links_commands_and_options():
    """The parsing the other tests rely on, on a text whose links and commands are known."""
    text = ("See [a](docs/a.md#two-words), ![p](x.png) and [w](https://example.org); `[no](b.md)`.\n\n"
            "    nodeforce locate B --weather W \\\n        --seed 0  # --not-an-option\n"
            "    nodeforce fmu B [--standalone]\n          [--x]\n\n"
            "```\n$ .venv/bin/nodeforce demo -o out\nmake demo\n```\n")
    blocks = code_blocks(text)
    assert [c for b in blocks for c in commands(b)] == [
        ("locate", ["--weather", "--seed"]), ("fmu", ["--standalone", "--x"]), ("demo", [])]
    page = ROOT / "tests" / "docs_parser_sample.md"
    try:
        page.write_text(text + "\n## Two words\n", encoding="utf-8")
        assert links(page) == ["docs/a.md#two-words", "x.png"]
        assert "two-words" in anchors(page)
    finally:
        page.unlink()
    assert slug("pythonfmu's known defects and the guard") == "pythonfmus-known-defects-and-the-guard"


def test_the_docs_show_commands():
    """The README and the guide show the commands, so the check below has something to check."""
    shown = {command for _, command, _ in shown_commands()}
    assert {"demo", "diagnose", "simulate", "locate", "fmu", "table", "synth"} <= shown


@pytest.mark.parametrize("page", PAGES + EXAMPLE_PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_relative_links_resolve(page):
    broken = []
    for target in links(page):
        path, _, anchor = target.partition("#")
        file = (page.parent / path).resolve() if path else page
        if not file.exists():
            broken.append(f"{target}: no file {file.relative_to(ROOT) if file.is_relative_to(ROOT) else file}")
        elif anchor and file.suffix == ".md" and anchor not in anchors(file):
            broken.append(f"{target}: no heading #{anchor} in {file.name}")
    assert not broken, f"{page.name}: " + "; ".join(broken)


@pytest.mark.parametrize("page,command,options", shown_commands(), ids=lambda v: v if isinstance(v, str) else None)
def test_documented_command_and_options_exist(page, command, options):
    status, text = help_text(command)
    assert status == 0, f"{page}: `nodeforce {command} --help` fails: {text.strip().splitlines()[-1:]}"
    listed = set(OPTION.findall(text))
    assert not set(options) - listed, f"{page}: nodeforce {command} has no {sorted(set(options) - listed)}"


# A file path in a code span: a slash, and a known ending; placeholders, globs and outputs left out.
PATH_SPAN = re.compile(r"`([A-Za-z0-9_.][A-Za-z0-9_./-]*/[A-Za-z0-9_.-]+\.(?:py|json|md|csv|txt|gz|c|h|toml|html|png|cfg))`")
# A name of the code: `model.network.assemble`, `diagnosis.policy.Policy.identifiable_kelvin`, ...
CODE_NAME = re.compile(r"`((?:model|diagnosis|ga|cosim|iotools|fmu_build|nodeforce)(?:\.[A-Za-z_][A-Za-z0-9_]*)+)`")
MODEL = ROOT / "docs" / "model.md"


def named_files(page):
    """The repository files a page names in code spans (`model/data/testcell.json`): paths whose
    first folder is the repository's or the page's; outputs of a run (`out/...`), a user's folders
    (`DIR/...`) and the inside of an FMU (`resources/...`) left out."""
    text = re.sub(r"```.*?```", "", page.read_text(encoding="utf-8"), flags=re.S)
    return sorted({p for p in PATH_SPAN.findall(text) if not p.startswith("out/")
                   and ((ROOT / p.split("/")[0]).exists() or (page.parent / p.split("/")[0]).exists())})


@pytest.mark.parametrize("page", PAGES + EXAMPLE_PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_file_the_docs_name_exists(page):
    """A path is the repository's (from its root) or the page's own folder's."""
    missing = [p for p in named_files(page) if not ((ROOT / p).exists() or (page.parent / p).exists())]
    assert not missing, f"{page.relative_to(ROOT)} names files that do not exist: {missing}"


def resolves(name):
    """Whether a dotted name of the code is a module, or an attribute of one (a function, a class,
    a method, a constant)."""
    import importlib
    parts = name.split(".")
    for cut in range(len(parts), 0, -1):
        module = "nodeforce" if parts[:cut] == ["nodeforce"] else "nodeforce." + ".".join(parts[:cut]).removeprefix("nodeforce.")
        try:
            found = importlib.import_module(module)
        except ImportError:
            continue
        for attribute in parts[cut:]:
            if not hasattr(found, attribute):
                return False
            found = getattr(found, attribute)
        return True
    return False


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_name_of_the_code_the_docs_give_exists(page):
    text = page.read_text(encoding="utf-8")
    names = {name for name in CODE_NAME.findall(text) if not re.search(r"\.(fmu|json|csv|md|py|png|txt)$", name)}
    wrong = sorted(name for name in names if not resolves(name))
    assert not wrong, f"{page.relative_to(ROOT)} names what the code does not have: {wrong}"


def test_the_names_check_tells_a_wrong_name():
    assert resolves("model.network.assemble") and resolves("model.case.Case.with_burn_in")
    assert resolves("iotools.hourly") and resolves("diagnosis.policy.Policy.identifiable_share")
    assert not resolves("model.network.no_such_function") and not resolves("model.no_such_module")


def documented_effects():
    """The effect ids of docs/model.md: the `### id` headings of its Effects section."""
    text = MODEL.read_text(encoding="utf-8")
    section = re.search(r"^## \d+\. Effects\n(.*?)(?=^## )", text, re.M | re.S)
    assert section, "docs/model.md has no '## N. Effects' section"
    return [h.strip("` ") for h in re.findall(r"^### (.+)$", section.group(1), re.M)]


def test_the_model_reference_documents_every_effect_of_the_registry():
    """One `### id` section per effect `model.effects.EFFECTS` registers, and none it does not: an
    effect added without its equations fails here."""
    from nodeforce.model.effects import EFFECTS
    documented = documented_effects()
    assert len(documented) == len(set(documented)), "an effect documented twice"
    assert set(documented) == set(EFFECTS), (f"undocumented: {sorted(set(EFFECTS) - set(documented))}; "
                                             f"not registered: {sorted(set(documented) - set(EFFECTS))}")
    # each section gives every parameter of the registry with its unit
    text = MODEL.read_text(encoding="utf-8")
    for effect_id, effect in EFFECTS.items():
        body = text.split(f"\n### {effect_id}\n", 1)[1].split("\n#", 1)[0]
        for p in effect.parameters:
            assert p.name in body, f"docs/model.md, {effect_id}: no parameter {p.name}"
            assert p.unit == "-" or p.unit in body, f"docs/model.md, {effect_id}: no unit {p.unit} of {p.name}"


def test_no_page_or_file_points_outside_the_repository():
    """The repository carries its own reference: no file names the specifications it grew from
    or a folder beside the clone (the words are assembled here so that this file passes too)."""
    words = ["PHYSICS" + ".md", "INTERFACE" + ".md", ".." + "/shared"]
    tracked = __import__("subprocess").run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True)
    found = []
    for name in tracked.stdout.decode().split("\0"):
        path = ROOT / name
        if not name or not path.is_file() or path.suffix in (".gz", ".png", ".fmu"):
            continue
        text = path.read_text(encoding="utf-8", errors="replace")
        found += [f"{name}: {w}" for w in words if w in text]
    assert not found, found


# A commit's short hash, as `git log --oneline` prints it.
HASH = re.compile(r"\b[0-9a-f]{7}\b")
RESULT_PAGES = ("performance.md", "benchmark_diagnosis.md")


@pytest.mark.parametrize("name", RESULT_PAGES)
def test_a_benchmark_page_is_a_reference_of_one_run(name):
    """At most 300 lines, and no commit but its run's, in its one run line."""
    lines = (ROOT / "docs" / name).read_text().splitlines()
    assert len(lines) <= 300
    hashes = [line for line in lines if HASH.search(line)]
    assert len(hashes) == 1 and hashes[0].startswith("Run: "), hashes


def test_the_readme_names_no_commit():
    assert not HASH.search((ROOT / "README.md").read_text())


def test_the_benchmark_pages_are_made_from_the_latest_results():
    """docs/performance.md's tables and docs/benchmark_diagnosis.md are what `benchmarks/pages.py`
    makes of the latest runs in benchmarks/results/."""
    import sys
    sys.path.insert(0, str(ROOT))
    from benchmarks.pages import pages
    for path, text in pages().items():
        assert path.read_text() == text, f"{path.name}: run python benchmarks/pages.py"


def test_the_pages_take_each_block_from_the_run_it_names(tmp_path):
    """A results block of a page is filled from the newest file of its benchmark, by date."""
    import json
    import sys
    sys.path.insert(0, str(ROOT))
    from benchmarks.pages import filled
    stamp = {"benchmark": "speed", "command": "c", "commit": "0000000", "machine": "m", "python": "3"}
    for date, figure in (("2026-01-02", "new"), ("2025-12-31", "old")):
        (tmp_path / f"speed-{date}.json").write_text(json.dumps({**stamp, "date": date, "search": {"tables": [figure]}}))
    text = "a\n<!-- results speed search -->\nstale\n<!-- /results -->\n<!-- results speed run -->\n<!-- /results -->\n"
    assert filled(text, tmp_path) == ("a\n<!-- results speed search -->\nnew\n<!-- /results -->\n"
                                      "<!-- results speed run -->\nRun: `c` on commit 0000000, 2026-01-02, m, Python 3."
                                      "\n<!-- /results -->\n")
