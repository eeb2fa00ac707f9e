"""Find and check the examples of the README and ``docs/*.md`` (used by ``test_docs_examples.py``).

Every fenced ``bash``/``sh``, ``python`` and ``toml`` block is an example. An HTML comment on the
line just before a block's fence (blank lines allowed between) sets how it is tested::

    <!-- docs-test: slow (why) -->    parsed in the default suite, run only with -m slow
    <!-- docs-test: parse (why) -->   only parsed (sbib lines by the argument parser, make targets
                                      against the Makefile, Python compiled, TOML validated)
    <!-- docs-test: skip (why) -->    not tested at all

Without a tag a block is parsed and run in the default suite. Blocks of one file run in document
order in one scratch folder, so a later block may read a file an earlier block wrote.
"""

from __future__ import annotations

import argparse
import importlib.util
import re
import shlex
import tomllib
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent

#: the documents whose examples are tested; docs/ARCHITECTURE.md is left out on purpose: its code
#: blocks are signatures of internal kernels, not examples to run
DOCUMENTS: tuple[Path, ...] = (REPO / "README.md",) + tuple(
    p for p in sorted((REPO / "docs").glob("*.md")) if p.name != "ARCHITECTURE.md")

LANGUAGES = {"bash": "bash", "sh": "bash", "shell": "bash", "python": "python", "toml": "toml"}
MODES = ("run", "slow", "parse", "skip")
_TAG = re.compile(r"^\s*<!--\s*docs-test:\s*(?P<mode>[\w-]+)\s*(?P<reason>.*?)\s*-->\s*$")
_FENCE = re.compile(r"^```(?P<lang>[\w+-]*)\s*$")
_INLINE_SBIB = re.compile(r"`(sbib [^`]+)`")
_INLINE_MODULE = re.compile(r"`(python -m [\w.]+[^`]*)`")


@dataclass(frozen=True)
class Block:
    """One fenced example: where it is, its language, its text and how it is tested."""

    document: Path
    line: int            # 1-based line of the opening fence
    language: str        # "bash", "python" or "toml"
    text: str
    mode: str            # one of MODES
    reason: str

    @property
    def id(self) -> str:
        return f"{self.document.relative_to(REPO)}:{self.line}"


def extract_blocks(text: str, document: Path = REPO / "README.md") -> list[Block]:
    """Return the example blocks of a Markdown text, with their test mode.

    Raises
    ------
    ValueError
        On an unknown tag, a tag before no block, or an unclosed fence (so that a typo in a tag
        never silently changes what is tested).
    """
    lines = text.split("\n")
    blocks: list[Block] = []
    pending: tuple[str, str, int] | None = None
    i = 0
    while i < len(lines):
        line = lines[i]
        tag = _TAG.match(line)
        if tag:
            mode = tag["mode"]
            if mode not in MODES:
                raise ValueError(f"{document.name}:{i + 1}: unknown docs-test tag {mode!r}; expected one of {MODES}")
            pending = (mode, tag["reason"].strip().strip("()").strip(), i + 1)
            i += 1
            continue
        fence = _FENCE.match(line)
        if fence:
            start = i
            i += 1
            while i < len(lines) and not lines[i].startswith("```"):
                i += 1
            if i >= len(lines):
                raise ValueError(f"{document.name}:{start + 1}: code block never closed")
            language = LANGUAGES.get(fence["lang"].lower())
            if language is not None:
                mode, reason = (pending[0], pending[1]) if pending else ("run", "")
                blocks.append(Block(document, start + 1, language, "\n".join(lines[start + 1:i]), mode, reason))
            elif pending:
                raise ValueError(f"{document.name}:{pending[2]}: docs-test tag before a "
                                 f"{fence['lang'] or 'plain'!r} block, which is never tested")
            pending = None
        elif line.strip() and pending:
            raise ValueError(f"{document.name}:{pending[2]}: docs-test tag is not followed by a code block")
        i += 1
    if pending:
        raise ValueError(f"{document.name}:{pending[2]}: docs-test tag is not followed by a code block")
    return blocks


def all_blocks() -> list[Block]:
    """Every example block of :data:`DOCUMENTS`, in document order."""
    return [b for doc in DOCUMENTS for b in extract_blocks(doc.read_text(encoding="utf-8"), doc)]


def shell_commands(text: str) -> list[list[str]]:
    """The commands of a shell block as token lists (continuations joined, comments dropped,
    ``&&``/``;``/``|`` split)."""
    joined = re.sub(r"\\\n", " ", text)
    commands: list[list[str]] = []
    for line in joined.split("\n"):
        tokens = shlex.split(line, comments=True)
        current: list[str] = []
        for token in tokens + [";"]:
            if token in ("&&", "||", ";", "|"):
                if current:
                    commands.append(current)
                current = []
            else:
                current.append(token)
    return commands


def _sbib_parser() -> argparse.ArgumentParser:
    from benchmark.applications.cli import build_parser

    return build_parser()


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:  # argparse keeps sub-parsers only here
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def check_sbib_command(argv: list[str]) -> None:
    """Parse ``sbib ARGV`` with the real parser; raise AssertionError with its message if it fails."""
    import contextlib
    import io

    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            args = _sbib_parser().parse_args(argv)
    except SystemExit as exc:
        if exc.code not in (0, None):
            raise AssertionError(f"'sbib {' '.join(argv)}' does not parse: {err.getvalue().strip()}") from None
        return
    if not getattr(args, "func", None):
        raise AssertionError(f"'sbib {' '.join(argv)}' names no command")


def check_mention(text: str) -> None:
    """Check an inline mention such as ``sbib identify [--out DIR] [--json]`` or
    ``sbib records list/show``: every sub-command word (and every ``/`` or ``|`` alternative) must exist
    and every ``--option`` must belong to the command it follows."""
    parser, parent = _sbib_parser(), None
    chain = ["sbib"]
    alternative = last_was_command = False
    for token in re.findall(r"[/|]|[^\s/|]+", text)[1:]:
        if token in "/|":
            alternative = last_was_command      # `records list / show` or `records show|generate`
            continue
        word = token.strip("[]()|,.;")
        if word.startswith("--"):
            option = re.match(r"--[a-z][a-z0-9-]*", word)
            if option and option[0] not in parser._option_string_actions:
                raise AssertionError(f"`{text}`: {' '.join(chain)} has no option {option[0]}")
        elif alternative and parent is not None:
            if word not in _subcommands(parent):
                raise AssertionError(f"`{text}`: {' '.join(chain[:-1])} has no sub-command {word!r}")
            parser = _subcommands(parent)[word]
            chain[-1] = word
            alternative, last_was_command = False, True
            continue
        elif _subcommands(parser) and word and not word.startswith("-"):
            if word in _subcommands(parser):
                parent, parser = parser, _subcommands(parser)[word]
                chain.append(word)
                alternative, last_was_command = False, True
                continue
            elif not (word.isupper() or word.startswith("<") or word == "..."):
                raise AssertionError(f"`{text}`: {' '.join(chain)} has no sub-command {word!r}")
        alternative = last_was_command = False


def inline_mentions(document: Path) -> list[str]:
    """The inline code spans of a document that start with ``sbib ``."""
    text = document.read_text(encoding="utf-8")
    return _INLINE_SBIB.findall(text)


def module_mentions(document: Path) -> list[str]:
    """The inline code spans of a document that start with ``python -m ``."""
    return _INLINE_MODULE.findall(document.read_text(encoding="utf-8"))


_HELP: dict[str, str] = {}


def check_module_mention(text: str) -> None:
    """Check an inline ``python -m MODULE [--option ...]``: the module runs with ``--help`` and
    lists every option the mention names."""
    import subprocess
    import sys

    module = text.split()[2]
    if module not in _HELP:
        proc = subprocess.run([sys.executable, "-m", module, "--help"], capture_output=True, text=True,
                              cwd=REPO, timeout=120)
        assert proc.returncode == 0, f"`{text}`: python -m {module} --help failed: {proc.stderr[-500:]}"
        _HELP[module] = proc.stdout
    for option in re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", text):
        assert re.search(rf"(?<![\w-]){re.escape(option)}(?![\w-])", _HELP[module]), \
            f"`{text}`: python -m {module} has no option {option}"


def makefile_targets() -> set[str]:
    text = (REPO / "Makefile").read_text(encoding="utf-8")
    return set(re.findall(r"^([A-Za-z][\w.-]*)\s*:(?!=)", text, flags=re.M))


def parse_block(block: Block) -> None:
    """Check a block without running it (see the module docstring)."""
    if block.language == "python":
        compile(block.text, block.id, "exec")
    elif block.language == "toml":
        data = tomllib.loads(block.text)
        if "controllers" in data or "records" in data:     # an ensemble description
            from benchmark.applications.ensemble import EnsembleConfig

            EnsembleConfig.from_dict(data, source=block.id, text=block.text)
    else:
        commands = shell_commands(block.text)
        assert commands, f"{block.id}: empty shell block"
        for argv in commands:
            if argv[0] == "sbib":
                check_sbib_command(argv[1:])
            elif argv[0] == "make":
                missing = [t for t in argv[1:] if not t.startswith("-") and "=" not in t
                           and t not in makefile_targets()]
                assert not missing, f"{block.id}: Makefile has no target {missing}"
            elif argv[0] in ("python", "python3") and argv[1:2] == ["-m"]:
                assert importlib.util.find_spec(argv[2]) is not None, f"{block.id}: no module {argv[2]}"


# --------------------------------------------------------------------------- the tests

import os  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402

import pytest  # noqa: E402

_BLOCKS = all_blocks()
_TIMEOUT = {"run": 300, "slow": 1800}


def _run_param(block: Block):
    marks = []
    if block.mode == "slow":
        marks.append(pytest.mark.slow)
    elif block.mode in ("parse", "skip"):
        marks.append(pytest.mark.skip(reason=f"{block.id} tagged docs-test: {block.mode} ({block.reason})"))
    return pytest.param(block, id=block.id, marks=marks)


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    """One scratch folder per document: <root>/work is the working directory, <root>/shared
    points at the shared data (so that ``../shared`` in an example works) and work/examples at
    the repository's examples."""
    folders: dict[Path, Path] = {}

    def get(document: Path, shared: Path) -> Path:
        if document not in folders:
            root = tmp_path_factory.mktemp(document.stem)
            (root / "shared").symlink_to(shared, target_is_directory=True)
            work = root / "work"
            work.mkdir()
            (work / "examples").symlink_to(REPO / "examples", target_is_directory=True)
            folders[document] = work
        return folders[document]

    return get


@pytest.mark.parametrize("block", [pytest.param(b, id=b.id) for b in _BLOCKS if b.mode != "skip"])
def test_docs_block_parses(block):
    """Every example parses: sbib lines by the real argument parser, Python compiles, TOML validates."""
    parse_block(block)


@pytest.mark.parametrize("mention", sorted({m for d in DOCUMENTS for m in inline_mentions(d)}))
def test_docs_inline_sbib_mentions_exist(mention):
    """Every inline `sbib ...` names commands and options that exist (no `records plot`)."""
    check_mention(mention)


@pytest.mark.parametrize("mention", sorted({m for d in DOCUMENTS for m in module_mentions(d)}))
def test_docs_inline_module_mentions_exist(mention):
    """Every inline `python -m MODULE --option` names a module and options that exist."""
    check_module_mention(mention)


def _all_sbib_options(parser: argparse.ArgumentParser, found: set[str]) -> set[str]:
    found.update(parser._option_string_actions)
    for sub in _subcommands(parser).values():
        _all_sbib_options(sub, found)
    return found


def test_docs_option_spans_name_real_options():
    """A code span that starts with an option (`--dt 0.01`, `--baseline-correct`) names an option
    that some sbib command has (the commands each belongs to are checked above)."""
    known = _all_sbib_options(_sbib_parser(), set())
    unknown = [f"{d.relative_to(REPO)}: {m}" for d in DOCUMENTS
               for m in re.findall(r"`(--[a-z][a-z0-9-]*)[^`]*`", d.read_text(encoding="utf-8"))
               if m not in known]
    assert not unknown, f"options no sbib command has: {unknown}"


@pytest.mark.parametrize("block", [_run_param(b) for b in _BLOCKS])
def test_docs_block_runs(block, scratch, shared_dir):
    """Every example runs (exit status 0) in its document's scratch folder."""
    work = scratch(block.document, shared_dir)
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONUNBUFFERED="1",
               PATH=str(Path(sys.executable).parent) + os.pathsep + os.environ.get("PATH", ""))
    env.setdefault("SBIB_SHARED", str(shared_dir))
    if block.language == "toml":
        parse_block(block)
        return
    if block.language == "python":
        script = work / f"_example_{block.document.stem}_{block.line}.py"
        script.write_text(block.text + "\n", encoding="utf-8")
        cmd = [sys.executable, str(script)]
    else:
        cmd = ["bash", "-euo", "pipefail", "-c", block.text]
    proc = subprocess.run(cmd, cwd=work, env=env, capture_output=True, text=True,
                          timeout=_TIMEOUT[block.mode])
    assert proc.returncode == 0, (f"{block.id} failed with status {proc.returncode}\n--- block\n{block.text}\n"
                                  f"--- stdout (end)\n{proc.stdout[-3000:]}\n--- stderr (end)\n{proc.stderr[-3000:]}")


# ------------------------------------------------------------------ the machinery itself

_SAMPLE = """Intro.

```bash
sbib run --record kobe
```

<!-- docs-test: slow (takes long) -->
```python
print(1)
```

<!-- docs-test: parse (placeholder file) -->

```sh
sbib records show my.AT2
```

```text
not an example
```
"""


def test_extract_blocks_reads_tags_and_languages():
    blocks = extract_blocks(_SAMPLE)
    assert [(b.language, b.mode, b.line) for b in blocks] == [("bash", "run", 3), ("python", "slow", 8),
                                                              ("bash", "parse", 14)]
    assert blocks[1].reason == "takes long" and blocks[0].text == "sbib run --record kobe"


@pytest.mark.parametrize("text, message", [
    ("<!-- docs-test: sloww -->\n```bash\nls\n```\n", "unknown docs-test tag"),
    ("<!-- docs-test: skip -->\nSome prose.\n```bash\nls\n```\n", "not followed by a code block"),
    ("<!-- docs-test: skip -->\n```text\nls\n```\n", "never tested"),
    ("```bash\nls\n", "never closed"),
])
def test_extract_blocks_rejects_tag_mistakes(text, message):
    with pytest.raises(ValueError, match=message):
        extract_blocks(text)


@pytest.mark.parametrize("command", [
    "sbib records plot kobe",                         # no such sub-command (the old README listed it)
    "sbib compare --records all [--json] [--jobs N]",  # usage brackets are not a command line
    "sbib run --recrd kobe",
])
def test_parse_check_catches_commands_that_do_not_exist(command):
    block = Block(REPO / "README.md", 1, "bash", command, "run", "")
    with pytest.raises(AssertionError, match="does not parse"):
        parse_block(block)


@pytest.mark.parametrize("mention", ["sbib records list/plot/report", "sbib records show|plot", "sbib records report",
                                     "sbib compare --out-dir DIR", "sbib identify [--outt DIR]"])
def test_mention_check_catches_what_does_not_exist(mention):
    with pytest.raises(AssertionError):
        check_mention(mention)


def test_module_mention_check_catches_unknown_options():
    check_module_mention("python -m benchmark.applications.fragility --out DIR --quick")
    with pytest.raises(AssertionError, match="no option --fast"):
        check_module_mention("python -m benchmark.applications.fragility --out DIR --fast")


def test_make_targets_are_checked():
    parse_block(Block(REPO / "README.md", 1, "bash", "make run\nmake test", "parse", ""))
    with pytest.raises(AssertionError, match="no target"):
        parse_block(Block(REPO / "README.md", 1, "bash", "make report", "parse", ""))
