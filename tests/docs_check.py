"""Run the commands and snippets of README.md and the site's Markdown pages (issue 25 item 4).

Usage::

    python tests/docs_check.py [--quick] [--list] [--keep] [PAGE ...]

``make docs-check`` runs it whole; ``make docs-check QUICK=1`` (and ``make test``, through
``tests/test_docs_run.py``) runs the quick form.

What is checked
---------------
Every fenced code block of the pages:

* ``python`` blocks run as a script (``python -``) in the page's working directory;
* shell blocks (no language, ``bash``, ``sh``, ``shell``, ``console``) run line by line with
  ``bash -c`` (a line ending in ``\\`` continues on the next; ``# ...`` ends a line's command).
  A block with lines starting ``$ `` is a transcript: those lines are the commands, the lines
  after each are its output as the page shows it, and the first output line up to its first
  digit must appear in the real output (whitespace-normalized). Optional groups ``[...]``
  (``[--json]``, ``[-j 2]``) are dropped from the command that runs, and every ``--flag`` in
  them must appear in that command's ``--help``;
* ``yaml`` blocks are loaded by the loader of the file format they show (``YAML_CHECKS``).

Inline code spans that are commands (``sweep ...``, ``make ...``, ``python -m ...``,
``python -c ...``, ``.venv/bin/...``) are checked too: ``python -c`` spans and those in
``INLINE_RUN`` run; the others are *references* to a command and are checked to exist (``make
-n TARGET``; ``sweep SUB --help`` or ``python -m MODULE SUB --help`` with every ``--flag`` of the
span in the help text; a module without a command line must import).

Each page runs in its own temporary directory holding a copy of the repository's tracked
``configs/`` and ``results/``, ``Makefile``, ``pyproject.toml`` and ``constraints.txt``, and
``.venv`` linked to this checkout's; the venv's ``bin`` is first on ``PATH`` (``sweep``,
``python`` resolve to it). The blocks of a page run in order and share that directory, as a
reader typing them would. ``/tmp/...`` paths in commands are redirected into it.

Commands that cannot run as written are mapped to what runs instead through ONE table,
``MAP`` below (quick form and full form, with the reason); placeholder files the pages name
(``FILE.yaml``, ``master.csv``, ``results/x.h5``) are made first by ``SETUP``; the quick form
reads the thinned ``QUICK=1`` outputs where the page reads a campaign's (``QUICK_SUBST``).
A block that cannot run at all carries, on the line before its opening fence,
``<!-- docs-check: skip (REASON) -->`` (the marker alone on its line; an inline command, the
same marker right before it); the runner reports it with its reason. Any other block
that fails, or whose language the runner does not know, fails the check with
``PAGE:LINE: ...``. Nothing is skipped silently: ``--list`` prints what runs, how, and why.
"""
from __future__ import annotations

import argparse
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# every Markdown page: the README and the site's pages (docs/, recursively; the site's own
# build folders are generated, not pages)
PAGES = ("README.md", "docs/getting-started.md", "docs/units.md", "docs/scenes.md",
         "docs/models.md", "docs/numerics.md", "docs/sweeps.md", "docs/configs.md",
         "docs/results.md", "docs/si.md", "docs/cluster.md", "docs/calibration.md",
         "docs/reproducing.md", "docs/speed.md", "docs/history.md", "docs/design.md",
         "docs/performance.md")
SKIP = re.compile(r"<!--\s*docs-check:\s*skip\s*\((.+)\)\s*-->")
SHELL_LANGS = {"", "bash", "sh", "shell", "console"}
# an inline code span that is a command: sweep/make/python with arguments, or a venv binary
INLINE_CMD = re.compile(r"^(time\s+)?(sweep|make|python3?|\.venv/bin/[\w-]+)(\s+\S.*)?$", re.S)

# ---------------------------------------------------------------------------------------
# THE table. (page, command as the page gives it, comment and [optional] groups removed)
# -> (quick form, full form, why). None: the command itself. The quick form is what
# `make test` runs (210 s for the 17 pages, one run, 2026-11-26); the full form `make docs-check`.
# ---------------------------------------------------------------------------------------
_R = "README.md"
_REPRO = "docs/reproducing.md"
MAP: dict[tuple[str, str], tuple[str | None, str | None, str]] = {
    (_R, "make test"): (
        "make -n test", "make -n test",
        "the docs check runs inside `make test`: running it here would run itself"),
    (_R, "make docs"): (
        "make -n docs", "make -n docs",
        "builds the whole site and runs the gallery (about 2-4 min); .ci/run runs it"),
    (_R, "make reproduce"): (
        "make -n reproduce QUICK=1", "make -n reproduce QUICK=1",
        "about 5 min; docs/reproducing.md runs its steps (quick: the thinned campaigns)"),
    (_R, "make reproduce QUICK=1"): (
        "make -n reproduce QUICK=1", "make reproduce QUICK=1 JOBS=1",
        "30 s; docs/reproducing.md runs its threshold and vr campaigns"),
    (_R, "make calibrate-demo"): (
        "make -n calibrate-demo", None,
        "about 5 min; the line above runs sweep calibrate on a tiny FILE.yaml"),
    ("docs/sweeps.md", "sweep run configs/threshold.yaml"): (
        "sweep run configs/quick/threshold.yaml --out results/quick/threshold/runs.h5 "
        "--progress none", None,
        "936 scenes: the quick form runs configs/quick/'s thinned grid"),
    # the campaigns: the quick form runs the two whose files the lines below read on the
    # Makefile's thinned grids (QUICK=1, about 7 s each); the fits, figures and report of the
    # pipeline run on synthetic files in tests/paper/test_reproduce.py
    (_REPRO, "make reproduce"): (
        "make -n reproduce QUICK=1", "make reproduce JOBS=1",
        "about 5 min (QUICK=1: 30 s); its steps are the lines below"),
    (_REPRO, "make threshold"): ("make threshold QUICK=1 JOBS=1", None, "the thinned grid"),
    (_REPRO, "make vr"): ("make vr QUICK=1 JOBS=1", None, "the thinned grid"),
    (_REPRO, "make fig3"): ("make -n fig3 QUICK=1", None,
                            "about 30 s (QUICK=1: 6 s); no later line reads its output"),
    (_REPRO, "make figures"): ("make -n figures QUICK=1", None,
                               "about 20 s (QUICK=1: 10 s); no later line reads its output"),
    (_REPRO, "make report"): ("make -n report QUICK=1", None,
                              "the report of the campaigns; tests/paper/test_reproduce.py runs "
                              "it on synthetic files"),
    (_REPRO, "make reproduce QUICK=1"): (
        "make -n reproduce QUICK=1", None,
        "30 s; its threshold and vr campaigns ran above (make threshold / vr QUICK=1)"),
    ("docs/si.md", "make pdms"): ("make -n pdms", None,
                                  "about 15 s; tests/paper/test_pdms.py covers sweep.paper.pdms"),
    ("docs/si.md", "make pdms-protocol"): (
        "make -n pdms-protocol", None,
        "a few minutes; tests/paper/test_pdms_protocol.py recomputes a point of it"),
    ("docs/si.md", "make pdms-bem"): (
        "make -n pdms-bem", None,
        "about 20 s when it resumes the committed results/pdms/bem.json (30 min without it)"),
    ("docs/calibration.md", "make calibrate-demo"): (
        "make -n calibrate-demo", None,
        "about 5 min; the line above runs sweep calibrate on a tiny FILE.yaml"),
    ("docs/models.md", "sweep scene --n 0.8 --k 0.5 --mu 30 --a0 20 --rate 1"): (
        "sweep scene --n 0.8 --k 0.5 --mu 100 --a0 15 --rate 1", None,
        "about 30 s: the quick form is a scene refused for too many steps before any solve"),
    ("docs/models.md", "sweep scene --n 0.8 --k 0.5 --mu 30 --a0 10 --rate 1e-4"): (
        "sweep scene --n 0.8 --k 0.5 --mu 100 --a0 15 --rate 1", None,
        "4 s to 65 s, by the machine's speed: the quick form is a scene refused for too many "
        "steps before any solve"),
}

# the quick form reads the QUICK=1 campaign outputs where a page reads the full campaign's
QUICK_SUBST = {
    "docs/sweeps.md": [("results/threshold.h5", "results/quick/threshold/runs.h5")],
    _REPRO: [("results/threshold/runs.h5", "results/quick/threshold/runs.h5"),
             ("results/vr/runs.h5", "results/quick/vr/runs.h5")],
}

# files a page names as placeholders or inputs, made in its directory before its blocks run
_TINY_CALIBRATION = """\
name: tiny
data: configs/calibrate/pulloff.csv
fixed: {R: 0.0103, E0: 1.0e6, nu: 0.5, h0: 3.08e-8, preload: 1.5e-3, Einf: 3.0e9, n: 0.22, tau0: 0.02}
fit: {dg: [0.05, 0.5]}
model: crack
search: {points: 2, starts: 1}
profile: {points: 3}
"""
_MASTER_CSV = """\
import numpy as np
from sweep.materials import MPLRetardation
w = np.logspace(-2, 19, 43)
E = MPLRetardation(E0=1.458e6, Einf=3.089e9, n=0.2207, tau0=0.01876).complex_modulus(w)
with open("master.csv", "w") as fh:
    fh.write("omega_rad_s,E_storage_Pa,E_loss_Pa\\n")
    fh.writelines(f"{a:.17g},{b.real:.17g},{b.imag:.17g}\\n" for a, b in zip(w, E))
"""
SETUP: dict[str, list[tuple[str, str]]] = {
    # (kind, text): kind "file:NAME" writes NAME, "python" runs the text, "sh" runs it
    _R: [("file:FILE.yaml", _TINY_CALIBRATION)],
    "docs/calibration.md": [("file:FILE.yaml", _TINY_CALIBRATION)],
    "docs/si.md": [("python", _MASTER_CSV)],
    "docs/results.md": [("sh", "sweep run configs/demo.yaml --out results/x.h5 --progress none")],
}

# yaml blocks: the loader of the format each page shows ({path}: the block written to a file)
YAML_CHECKS = {
    _R: "from sweep.campaign.config import load_config\n"
        "cfg = load_config('{path}'); print(cfg.name, len(cfg.scenes()), 'scenes')",
    "docs/calibration.md": "from sweep.analysis.calibrate import load_calibration\n"
                           "import shutil; shutil.copy('configs/calibrate/pulloff.csv', "
                           "'pulloff.csv')\n"
                           "cal = load_calibration('{path}'); print(cal)",
    "docs/configs.md": "from sweep.campaign.config import load_config\n"
                       "cfg = load_config('{path}'); print(cfg.name, len(cfg.scenes()), 'scenes')",
}

# inline spans that run (not only checked to exist): what their output must contain, and
# their exit status (`sweep scene` exits 1 when the scene failed)
INLINE_RUN: dict[tuple[str, str], tuple[tuple[str, ...], int]] = {
    ("docs/numerics.md",
     "sweep scene --n 0.4 --k 0.1 --mu 3.24 --a0 2 --rate 1 --preset fast --nodes 60"):
        # the change itself (0.68 here, 0.67 on 2026-11-25) is left out: its second digit
        # moves with the numerics and the processor
        (("failed (unresolved: the pull-off moves by ",), 1),
}

# what a command must print where the page says what it prints; for a transcript, in place of
# the first line the page shows where that line depends on the machine (the page says so)
CHECKS: dict[tuple[str, str], tuple[str, ...]] = {
    # "prints where results and figure are"
    (_R, "make demo"): ("results: results/demo.h5", "figure: results/demo.png"),
    ("docs/getting-started.md", "make demo"): ("results: results/demo.h5",
                                               "figure: results/demo.png"),
    # ends on max_steps after 63323 steps (28 s on this VM; its time budget would end it
    # first only on a machine ten times slower)
    ("docs/models.md", "sweep scene --n 0.8 --k 0.5 --mu 30 --a0 20 --rate 1"):
        ("status failed (",),
    # ends on its time budget after the probe or after a later chunk, by the machine's speed
    ("docs/models.md", "sweep scene --n 0.8 --k 0.5 --mu 30 --a0 10 --rate 1e-4"):
        ("status failed (",),
}


@dataclass
class Block:
    """One fenced code block or inline command of a page."""

    page: str
    line: int
    lang: str            # python, yaml, shell, console, inline, or the fence's own word
    text: str
    skip: str | None = None

    @property
    def where(self) -> str:
        return f"{self.page}:{self.line}"


@dataclass
class Step:
    """One thing the runner executes for a block, and why it is that."""

    block: Block
    kind: str            # sh, python, yaml
    text: str
    how: str             # "as written", "mapped: why", "reference", "setup"
    expect: list[str] = field(default_factory=list)
    help_flags: list[str] = field(default_factory=list)
    code: int = 0        # the exit status it must end with


class DocsCheckError(AssertionError):
    """A block of the docs failed: the message names the page and line."""


def blocks(page: str, text: str | None = None) -> list[Block]:
    """The fenced blocks and inline commands of ``page``, in the order of the page.

    Parameters
    ----------
    page : str
        Path relative to the repository root.
    text : str, optional
        The page's text (default: read it).

    Returns
    -------
    list of Block
    """
    text = (ROOT / page).read_text() if text is None else text
    lines = text.splitlines()
    out: list[Block] = []
    prose = list(lines)
    i = 0
    while i < len(lines):
        s = lines[i].strip()
        if s.startswith("```"):
            lang = s[3:].strip().lower()
            j = i + 1
            while j < len(lines) and lines[j].strip() != "```":
                j += 1
            if j == len(lines):
                raise DocsCheckError(f"{page}:{i + 1}: fence never closed")
            k = i - 1
            while k >= 0 and not lines[k].strip():
                k -= 1
            m = SKIP.fullmatch(lines[k].strip()) if k >= 0 else None    # the marker's own line
            body = "\n".join(lines[i + 1:j])
            kind = ("console" if re.search(r"^\s*\$ ", body, re.M) else "shell") \
                if lang in SHELL_LANGS else {"py": "python", "yml": "yaml"}.get(lang, lang)
            out.append(Block(page, i + 1, kind, body, m.group(1) if m else None))
            for n in range(i, j + 1):
                prose[n] = ""
            i = j + 1
            continue
        i += 1
    joined = "\n".join(prose)
    for m in re.finditer(r"`([^`]+)`", joined):
        span = m.group(1)
        if not INLINE_CMD.match(span.strip()):
            continue
        # an inline command is skipped by a marker right before it (whitespace between)
        sk = re.search(SKIP.pattern + r"\s*$", joined[max(0, m.start() - 300):m.start()])
        out.append(Block(page, joined.count("\n", 0, m.start()) + 1, "inline",
                         " ".join(span.split()), sk.group(1) if sk else None))
    return sorted(out, key=lambda b: b.line)


def _commands(block: Block) -> list[tuple[str, list[str]]]:
    """A shell block's commands, each with the output lines the page shows after it."""
    lines, cmds = block.text.splitlines(), []
    joined: list[str] = []
    for ln in lines:
        if joined and joined[-1].endswith("\\"):
            joined[-1] = joined[-1][:-1].rstrip() + " " + ln.strip()
        else:
            joined.append(ln)
    for ln in joined:
        if block.lang == "console":
            if ln.lstrip().startswith("$ "):
                cmds.append((ln.lstrip()[2:], []))
            elif cmds and ln.strip():
                cmds[-1][1].append(ln.strip())
        elif ln.strip():
            cmds.append((ln.strip(), []))
    return cmds


def _strip(cmd: str) -> tuple[str, list[str]]:
    """A command without its trailing comment and optional ``[...]`` groups, and the flags of
    those groups."""
    cmd = re.sub(r"(^|\s)#(\s.*)?$", "", cmd).strip()
    flags = [f for g in re.findall(r"\[([^\]]*)\]", cmd) for f in re.findall(r"--[\w-]+", g)]
    cmd = re.sub(r"\s*\[[^\]]*\]", "", cmd).strip()
    return " ".join(cmd.split()), flags


def _help_command(cmd: str) -> str | None:
    """The ``--help`` of the command a line runs (sweep SUB, python -m MODULE [SUB])."""
    w = shlex.split(cmd)
    if w and w[0] == "time":
        w = w[1:]
    if w and w[0].endswith("sweep"):
        sub = []                                   # sweep fit threshold: a group's command
        for x in w[1:3]:
            if not re.fullmatch(r"[a-z][a-z-]*", x):
                break
            sub.append(x)
        return " ".join(["sweep", *sub, "--help"])
    if len(w) >= 3 and w[0].startswith("python") and w[1] == "-m":
        src = _module_source(w[2])
        if src is None or not re.search(r"argparse|click", src):
            return None
        sub = [x for x in w[3:4] if not x.startswith("-") and x != "..." and x.islower()
               and "argparse" not in src]
        return " ".join(["python", "-m", w[2], *sub, "--help"])
    return None


def _module_source(module: str) -> str | None:
    parts = module.split(".")
    if parts[:2] == ["sweep", "kernels"]:
        parts = ["kernels", *parts[2:]]
    for p in (ROOT.joinpath(*parts).with_suffix(".py"), ROOT.joinpath(*parts, "__main__.py")):
        if p.is_file():
            return p.read_text()
    return None


def _reference(block: Block, cmd: str) -> Step | list[Step]:
    """The check that an inline command exists: make -n, or its --help names its flags."""
    w = cmd.split()
    if w[0] == "time":
        w = w[1:]
    w[0] = re.sub(r"^\.venv/bin/", "", w[0])
    cmd = " ".join(w)
    if w[0] == "make":
        targets = [x for x in w[1:] if "=" not in x and x != "..."]
        variables = [x for x in w[1:] if "=" in x]
        return Step(block, "sh", " && ".join(f"make -n {t} {' '.join(variables)} >/dev/null"
                                             for t in targets or ["help"]), "reference")
    flags = [f for f in re.findall(r"(?<!\S)--[\w-]+", cmd)]
    if len(w) == 1 and w[0].startswith("python"):
        return Step(block, "sh", f"{w[0]} --version", "reference")
    if len(w) >= 4 and "|" in w[3]:                # python -m MODULE a|b|c: each subcommand
        return [Step(block, "sh", _help_command(" ".join([*w[:3], sub])), "reference")
                for sub in w[3].split("|")]
    if len(w) >= 3 and w[0].startswith("python") and w[1] == "-m":
        helper = _help_command(cmd)
        if helper is None:
            return Step(block, "python",
                        f"import importlib.util as u\nassert u.find_spec({w[2]!r}), {w[2]!r}",
                        "reference (module imports)")
        return Step(block, "sh", helper, "reference", help_flags=flags)
    if w[0] == "sweep":
        return Step(block, "sh", _help_command(cmd), "reference", help_flags=flags)
    return Step(block, "sh", cmd, "reference")


def plan(page: str, quick: bool) -> list[Step]:
    """What the runner executes for ``page`` (setup first), in order.

    Parameters
    ----------
    page : str
        Path of the page relative to the repository root.
    quick : bool
        The quick form (``MAP``'s quick column and ``QUICK_SUBST``).

    Returns
    -------
    list of Step

    Raises
    ------
    DocsCheckError
        A block of a language the runner cannot run and that carries no skip marker.
    """
    steps: list[Step] = []
    setup_block = Block(page, 0, "setup", "")
    for kind, text in SETUP.get(page, []):
        if kind.startswith("file:"):
            steps.append(Step(setup_block, "file", f"{kind[5:]}\n{text}", "setup"))
        else:
            steps.append(Step(setup_block, kind, text, "setup"))

    def subst(text: str) -> str:
        text = re.sub(r"(?<![\w.])/tmp/", "tmp/", text)
        for old, new in QUICK_SUBST.get(page, []) if quick else []:
            text = text.replace(old, new)
        return text

    for b in blocks(page):
        if b.skip is not None:
            steps.append(Step(b, "skip", b.text, f"skip ({b.skip})"))
            continue
        if b.lang == "python":
            steps.append(Step(b, "python", subst(b.text), "as written"))
        elif b.lang == "yaml":
            if page not in YAML_CHECKS:
                raise DocsCheckError(f"{b.where}: a yaml block with no loader in YAML_CHECKS "
                                     "(add one, or mark it <!-- docs-check: skip (why) -->)")
            steps.append(Step(b, "yaml", b.text, "loaded"))
        elif b.lang in ("shell", "console"):
            for raw, shown in _commands(b):
                cmd, flags = _strip(raw)
                quick_cmd, full_cmd, why = MAP.get((page, cmd), (None, None, ""))
                run = quick_cmd if quick else full_cmd
                how = f"mapped: {why}" if run is not None else "as written"
                expect, code = [], 0
                if not (run or "").endswith("--help"):
                    expect = list(CHECKS.get((page, cmd), ()))
                if shown and not (run or "").endswith("--help"):
                    expect = expect or [re.split(r"\d", shown[0], maxsplit=1)[0].strip()]
                    # a transcript of a failed scene: `sweep scene` exits 1
                    code = 1 if re.match(r"status\s+failed", shown[0]) else 0
                steps.append(Step(b, "sh", subst(run if run is not None else cmd), how,
                                  expect, code=code))
                if flags:
                    helper = _help_command(cmd)
                    if helper:
                        steps.append(Step(b, "sh", helper, "reference ([optional] flags)",
                                          help_flags=flags))
        elif b.lang == "inline":
            cmd, flags = _strip(b.text)
            if re.match(r"^(\.venv/bin/)?python3? -c ", cmd):
                steps.append(Step(b, "sh", subst(cmd), "as written"))
            elif (page, cmd) in INLINE_RUN:
                expect, code = INLINE_RUN[(page, cmd)]
                steps.append(Step(b, "sh", subst(cmd), "as written", list(expect), code=code))
            else:
                ref = _reference(b, cmd)
                steps.extend(ref if isinstance(ref, list) else [ref])
        else:
            raise DocsCheckError(f"{b.where}: a ```{b.lang} block the runner cannot run "
                                 "(mark it <!-- docs-check: skip (why) --> or teach the runner)")
    return steps


def workdir(base: Path) -> Path:
    """A working directory like a fresh checkout: tracked configs/, results/ and the sample
    Prony tables of tests/data/prony/ (the pages' table configs read them), the Makefile and
    the files its venv stamp depends on (their times kept), ``.venv`` linked."""
    dirs = ("configs", "results", "tests/data/prony")
    try:
        tracked = subprocess.run(["git", "ls-files", *dirs], cwd=ROOT,
                                 capture_output=True, text=True, check=True).stdout.split()
    except (OSError, subprocess.CalledProcessError):
        tracked = [str(p.relative_to(ROOT)) for d in dirs
                   for p in (ROOT / d).rglob("*") if p.is_file()]
    for rel in tracked + ["Makefile", "pyproject.toml", "constraints.txt"]:
        dst = base / rel
        dst.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / rel, dst)
    (base / "tmp").mkdir(exist_ok=True)
    (base / ".venv").symlink_to(ROOT / ".venv")
    return base


def _env() -> dict:
    env = dict(os.environ)
    venv_bin = str(ROOT / ".venv" / "bin")
    env["PATH"] = venv_bin + os.pathsep + env.get("PATH", "")
    env["VIRTUAL_ENV"] = str(ROOT / ".venv")
    env["MPLBACKEND"] = "Agg"
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
        env.setdefault(var, "1")
    env.pop("MAKEFLAGS", None)
    env.pop("MFLAGS", None)
    env.pop("MAKELEVEL", None)
    return env


def _norm(text: str) -> str:
    return " ".join(text.split())


_HELP: dict[str, subprocess.CompletedProcess] = {}
_CLICK_HELP = """\
import importlib, json, sys
import click
m = importlib.import_module(sys.argv[1])
group = next(v for v in vars(m).values() if isinstance(v, click.Group))
out = {}
for name, cmd in group.commands.items():
    with click.Context(cmd, info_name=name) as ctx:
        out[name] = cmd.get_help(ctx)
print(json.dumps(out))
"""


def _click_help(text: str, cwd: Path) -> subprocess.CompletedProcess | None:
    """``python -m MODULE SUB --help`` of a click group, all of a module's commands in one
    process (importing such a module takes a second or two)."""
    m = re.fullmatch(r"python -m ([\w.]+) ([\w-]+) --help", text)
    if not m or "click" not in (_module_source(m.group(1)) or ""):
        return None
    key = f"click:{m.group(1)}"
    if key not in _HELP:
        _HELP[key] = subprocess.run([str(ROOT / ".venv" / "bin" / "python"), "-c", _CLICK_HELP,
                                     m.group(1)], cwd=cwd, env=_env(), capture_output=True,
                                    text=True, timeout=120)
    done = _HELP[key]
    if done.returncode != 0:
        return done
    import json
    helps = json.loads(done.stdout)
    if m.group(2) not in helps:
        return subprocess.CompletedProcess(text, 2, "", f"no command {m.group(2)!r}")
    return subprocess.CompletedProcess(text, 0, helps[m.group(2)], "")


def run_step(step: Step, cwd: Path, timeout: float) -> str:
    """Run one step in ``cwd``; raise DocsCheckError naming the page and line on failure."""
    where = step.block.where if step.block.line else f"{step.block.page} (setup)"
    if step.kind == "skip":
        return ""
    if step.kind == "file":
        name, text = step.text.split("\n", 1)
        (cwd / name).write_text(text)
        return ""
    if step.kind == "python":
        argv, stdin = [str(ROOT / ".venv" / "bin" / "python"), "-"], step.text
    elif step.kind == "yaml":
        (cwd / "block.yaml").write_text(step.text)
        argv, stdin = [str(ROOT / ".venv" / "bin" / "python"), "-"], \
            YAML_CHECKS[step.block.page].format(path="block.yaml")
    else:
        argv, stdin = ["bash", "-c", "set -o pipefail; " + step.text], None
    try:
        # a --help or make -n is the same in every directory: run each once
        pure = step.kind == "sh" and re.fullmatch(r"[^;&|]*--help|make -n [^;&|]*", step.text)
        proc = (_HELP.get(step.text) or _click_help(step.text, cwd)) if pure else None
        if proc is None:
            proc = subprocess.run(argv, input=stdin, cwd=cwd, env=_env(), capture_output=True,
                                  text=True, timeout=timeout)
        if pure:
            _HELP[step.text] = proc
    except subprocess.TimeoutExpired:
        raise DocsCheckError(f"{where}: `{_first(step.text)}` took more than {timeout:.0f} s") \
            from None
    out = proc.stdout + proc.stderr
    if proc.returncode != step.code:
        last = [ln for ln in out.strip().splitlines() if ln.strip()][-1:] or ["(no output)"]
        raise DocsCheckError(f"{where}: `{_first(step.text)}` exited {proc.returncode} "
                             f"(expected {step.code}): "
                             f"{last[0].strip()[:300]}")
    for flag in step.help_flags:
        if not re.search(re.escape(flag) + r"(?![\w-])", out):
            raise DocsCheckError(f"{where}: `{_first(step.text)}` does not know {flag}")
    for want in step.expect:
        if not printed(want, out):
            raise DocsCheckError(f"{where}: `{_first(step.text)}` did not print {want!r} "
                                 f"(numbers to {NUMBER_RTOL:.0%}; got: {_norm(out)[:200]!r})")
    return out


# A number a page quotes from a command's output is compared to a relative tolerance, not as
# text: some quoted values are differences of unresolved results (the pull-off change between
# two coarse meshes, README's 60-node scene), whose second digit moves with the processor's
# floating point (0.67 on one machine, 0.68 on another, the same code). The words around the
# numbers (statuses, reasons, units) must match exactly; a number's sign and size to 5 %.
NUMBER_RTOL = 0.05
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def printed(want: str, out: str, rtol: float = NUMBER_RTOL) -> bool:
    """Whether ``out`` contains ``want``: its words exactly (whitespace-normalized), its numbers
    each within ``rtol`` of the number printed in their place.

    Parameters
    ----------
    want : str
        What the page says the command prints.
    out : str
        What the command printed.
    rtol : float
        Relative tolerance of each number (an exact zero must be printed as zero).

    Returns
    -------
    bool
    """
    want, out = _norm(want), _norm(out)
    parts = _NUMBER.split(want)
    numbers = [float(x) for x in _NUMBER.findall(want)]
    if not numbers:
        return want in out
    pattern = r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)".join(re.escape(p) for p in parts)
    for m in re.finditer(f"(?={pattern})", out):
        got = [float(x) for x in m.groups()]
        if all(abs(g - w) <= rtol * abs(w) for g, w in zip(got, numbers)):
            return True
    return False


def _first(text: str) -> str:
    return text.strip().splitlines()[0][:120] if text.strip() else ""


def check_page(page: str, quick: bool, keep: bool = False, say=print) -> dict:
    """Run every step of ``page`` in a fresh working directory.

    Parameters
    ----------
    page : str
        Path relative to the repository root.
    quick : bool
        The quick form.
    keep : bool
        Keep the working directory (its path is printed).
    say : callable
        Progress lines.

    Returns
    -------
    dict
        Counts of the steps by how they ran, the skipped blocks with their reasons, the wall.

    Raises
    ------
    DocsCheckError
        The first step that failed (the message names the page and line).
    """
    steps = plan(page, quick)
    base = Path(tempfile.mkdtemp(prefix="docs-check-"))
    t0 = time.perf_counter()
    counts: dict[str, int] = {}
    try:
        cwd = workdir(base)
        for step in steps:
            s = time.perf_counter()
            run_step(step, cwd, timeout=300 if quick else 7200)
            key = step.how.split(":")[0].split(" (")[0]
            counts[key] = counts.get(key, 0) + 1
            where = step.block.where if step.block.line else f"{page} (setup)"
            say(f"  {where:24s} {time.perf_counter() - s:6.1f} s  {step.how[:60]:60s} "
                f"{_first(step.text)[:70]}")
    finally:
        if keep:
            say(f"  kept {base}")
        else:
            shutil.rmtree(base, ignore_errors=True)
    return {"page": page, "counts": counts, "wall_s": time.perf_counter() - t0,
            "skipped": [(s.block.where, s.how) for s in steps if s.kind == "skip"]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("pages", nargs="*", default=list(PAGES))
    ap.add_argument("--quick", action="store_true", help="the quick form (make test)")
    ap.add_argument("--list", action="store_true", help="print the plan, run nothing")
    ap.add_argument("--keep", action="store_true", help="keep the working directories")
    args = ap.parse_args(argv)
    if args.list:
        totals: dict[str, int] = {}
        fenced = inline = 0
        for page in args.pages:
            fenced += sum(b.lang != "inline" for b in blocks(page))
            inline += sum(b.lang == "inline" for b in blocks(page))
            for s in plan(page, args.quick):
                print(f"{s.block.where:24s} {s.kind:6s} {s.how[:70]:70s} {_first(s.text)[:80]}")
                key = s.how.split(":")[0].split(" (")[0]
                totals[key] = totals.get(key, 0) + 1
        print(f"{fenced} fenced blocks, {inline} inline commands; steps: {totals}")
        return 0
    total, failed, counts = time.perf_counter(), 0, {}
    for page in args.pages:
        print(f"{page}:")
        try:
            res = check_page(page, args.quick, args.keep)
        except DocsCheckError as exc:
            print(f"FAILED {exc}")
            failed += 1
            continue
        print(f"  {page}: {res['counts']} in {res['wall_s']:.1f} s")
        for key, n in res["counts"].items():
            counts[key] = counts.get(key, 0) + n
    print(f"docs check ({'quick' if args.quick else 'full'}): {len(args.pages) - failed} of "
          f"{len(args.pages)} pages pass, {time.perf_counter() - total:.0f} s; steps {counts}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
