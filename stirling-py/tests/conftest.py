"""Shared helpers of the Python tests: the `stirling` command line to compare against.

The command line comes from `STIRLING_CLI` (`.ci/run` exports the binary `cargo test
--workspace` built, `target/debug/stirling`); without it, that path under `CARGO_TARGET_DIR`
or the repository's `target/`. A missing binary fails the tests that need it: they are never
skipped.
"""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def cli_path() -> Path:
    given = os.environ.get("STIRLING_CLI")
    if given:
        return Path(given)
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    return target / "debug" / "stirling"


@pytest.fixture(scope="session")
def cli():
    """Run the command line; returns its stdout (JSON parsed when `--json` is given)."""
    path = cli_path()
    if not path.is_file():
        pytest.fail(
            f"the stirling command line is not at {path}: build it (cargo build -p stirling-cli) "
            "or point STIRLING_CLI at it (.ci/run does)"
        )

    def run(*args: str):
        out = subprocess.run([str(path), *args], capture_output=True, text=True)
        assert out.returncode == 0, f"stirling {' '.join(args)} failed:\n{out.stderr}"
        return json.loads(out.stdout) if "--json" in args else out.stdout

    return run


def close(a, b, rel: float, what: str = "") -> None:
    """Every number of `a` within `rel` (relative to the larger magnitude) of `b`'s; nested
    lists and dicts compared entry by entry, other values equal."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), f"{what}: keys {sorted(a)} vs {sorted(b)}"
        for k in a:
            close(a[k], b[k], rel, f"{what}.{k}")
    elif isinstance(a, (list, tuple)):
        assert isinstance(b, (list, tuple)) and len(a) == len(b), f"{what}: lengths {len(a)} vs {len(b)}"
        for i, (x, y) in enumerate(zip(a, b)):
            close(x, y, rel, f"{what}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        scale = max(abs(a), abs(b))
        assert abs(a - b) <= rel * scale, f"{what}: {a!r} vs {b!r} (rel {rel})"
    else:
        assert a == b, f"{what}: {a!r} vs {b!r}"
