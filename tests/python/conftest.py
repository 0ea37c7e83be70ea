"""Shared fixtures: the rdyn CLI from the same build (RDYN_BINARY), run through one helper."""
import json
import os
import subprocess

import pytest


@pytest.fixture(scope="session")
def rdyn_cli():
    binary = os.environ["RDYN_BINARY"]

    def run(*args, expect=0):
        # An argument vector, no shell.
        p = subprocess.run([binary, *args], capture_output=True, text=True)
        assert p.returncode == expect, p.stderr
        return p
    return run


def read_csv(path):
    """A CSV rdyn wrote, as {column: list of floats} (the '#' lines skipped)."""
    with open(path) as f:
        lines = [l for l in f.read().splitlines() if l and not l.startswith("#")]
    header = lines[0].split(",")
    rows = [[float(x) for x in l.split(",")] for l in lines[1:]]
    return {h: [r[i] for r in rows] for i, h in enumerate(header)}


def read_json(path):
    with open(path) as f:
        return json.load(f)
