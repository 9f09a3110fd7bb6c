"""The argument fuzzer's contract (fuzz_arguments.py) on a fixed draw: 300 random calls of every
Python entry point with awkward arguments either succeed or raise oralfluor.InputError, and every
finding of the 10-minute campaigns, kept in fuzz_regressions.json, stays fixed."""
import json
import os
import random

import numpy as np
import pytest

import oralfluor as ofl
import fuzz_arguments as fz

REGRESSIONS = json.load(open(os.path.join(os.path.dirname(__file__), "fuzz_regressions.json")))


@pytest.fixture(scope="module")
def harness(tmp_path_factory):
    tmp = str(tmp_path_factory.mktemp("fuzz"))
    here = os.getcwd()
    os.chdir(tmp)  # relative output names land in the scratch folder, not the source tree
    yield fz.make_pool(ofl, np, tmp), fz.entries(ofl)
    os.chdir(here)


@pytest.mark.parametrize("case", REGRESSIONS, ids=[f"{c['case'][0]}-{i}" for i, c in enumerate(REGRESSIONS)])
def test_campaign_findings_stay_fixed(harness, case):
    pool, table = harness
    assert fz.run_case(ofl, pool, table, case["case"]) is None, case["was"]


def test_random_calls_succeed_or_raise_input_error(harness):
    pool, table = harness
    rng = random.Random(27)
    keys = sorted(pool)
    problems = []
    for _ in range(300):
        case = fz.random_case(rng, table, keys)
        p = fz.run_case(ofl, pool, table, case)
        if p:
            problems.append((case, p))
    assert problems == []
