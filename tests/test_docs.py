"""The documentation stays true: every relative link in README.md and docs/*.md resolves (the
file, and a `#anchor` to a heading of a Markdown file), and every `nodeforce COMMAND` shown in a
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
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]

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


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
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
