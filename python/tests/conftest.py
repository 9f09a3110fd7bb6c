"""Shared fixtures: where the source tree and the oralfluor binary are, and a CLI runner.

ctest sets OFL_SOURCE_DIR, OFL_BINARY and PYTHONPATH=build/python (CMakeLists.txt); by hand:
    PYTHONPATH=build/python OFL_BINARY=build/oralfluor /usr/bin/python3 -m pytest python/tests
"""
import json
import os
import subprocess

import pytest

ROOT = os.path.abspath(os.environ.get("OFL_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..")))
BINARY = os.path.abspath(os.environ.get("OFL_BINARY", os.path.join(ROOT, "build", "oralfluor")))


def run_cli(*args, check=True):
    """Runs the oralfluor binary; returns the CompletedProcess (stdout, stderr as text)."""
    env = dict(os.environ, OFL_NO_PROGRESS="1")
    p = subprocess.run([BINARY, *map(str, args)], capture_output=True, text=True, env=env)
    if check and p.returncode != 0:
        raise AssertionError(f"oralfluor {' '.join(map(str, args))} exited {p.returncode}:\n{p.stderr}")
    return p


def cli_json(*args):
    return json.loads(run_cli(*args, "--json").stdout)


@pytest.fixture
def root():
    return ROOT


def scene_path(*parts):
    return os.path.join(ROOT, "scenes", *parts)
