"""bench/explore_vs_grid.py: its hypervolume logic on synthetic data (--self-check), and a whole
run against a stand-in for `sfx explore` that prints the agreed JSON (no real sfx needed)."""

import json
import os
import subprocess
import sys

BENCH = os.path.join(os.path.dirname(__file__), "..", "..", "bench", "explore_vs_grid.py")

# A stand-in sfx: a 4 x 4 grid space (fps max, area min), --exhaustive screens all 16;
# a search screens the configs given by SEARCH (its own values are junk: the bench must use the
# grid's).
FAKE = r'''
import json, sys
args = sys.argv[1:]
assert args[0] == "explore" and "--json" in args and "--store" in args
configs = []
for i in range(16):  # a = i % 4, b = i // 4; b > 0 is worse in both: configs 0-3 are the front
    fps = 10.0 + 5 * (i % 4) - (i // 4)
    area = 20.0 + 4 * (i % 4) + 3 * (i // 4)
    configs.append({"config": i, "knobs": {"hw.simd.width": str(i)}, "values": [fps, area],
                    "feasible": area <= 40})
objs = [{"metric": "fps", "direction": "maximize"}, {"metric": "area_mm2", "direction": "minimize"}]
if "--exhaustive" in args:
    doc = {"explore": "fake", "configurations": 16, "evaluations": 16, "seconds": 0.1,
           "objectives": objs, "screened": configs, "front": [], "screen_front": []}
else:
    seed = int(args[args.index("--seed") + 1])
    assert "--study" in args and args[args.index("--sampler") + 1] == "tpe"
    chosen = SEARCH[seed]
    doc = {"explore": "fake", "configurations": 16, "evaluations": len(chosen), "seconds": 0.1,
           "objectives": objs,
           "screened": [dict(configs[i] if i < 16 else {"config": i}, values=[0, 0])
                        for i in chosen],
           "front": [], "screen_front": []}
print("progress noise")
print(json.dumps(doc))
'''


def fake_sfx(tmp_path, search):
    path = tmp_path / "fake_sfx"
    path.write_text(f"#!{sys.executable}\nSEARCH = {search!r}\n" + FAKE)
    path.chmod(0o755)
    return str(path)


def run(tmp_path, search, seeds="1,2,3"):
    sfx = fake_sfx(tmp_path, search)
    return subprocess.run([sys.executable, BENCH, sfx, "x.yaml", str(tmp_path / "w"),
                           "--seeds", seeds, "--samplers", "tpe"], capture_output=True, text=True, timeout=120)


def test_self_check():
    done = subprocess.run([sys.executable, BENCH, "--self-check"], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "self-check" in done.stdout


def test_whole_run_with_a_stand_in(tmp_path):
    # 15 configurations are feasible (area <= 40: all but config 15), 4 on the front.
    front = [0, 1, 2, 3]
    done = run(tmp_path, {1: front, 2: front + [5], 3: [0, 1, 3]}, seeds="1,3")
    assert done.returncode in (0, 1), done.stderr
    result = json.load(open(tmp_path / "w" / "explore_vs_grid.json"))
    shares = [r["hv_share"] for r in result["samplers"]["tpe"]["seeds"]]
    assert abs(shares[0] - 1.0) < 1e-12 and shares[1] < 1.0
    assert result["grid"] == {"configurations": 16, "feasible": 15, "front": 4}
    assert "median over 2 seeds" in done.stdout


def test_target_met_and_missed(tmp_path):
    front = [0, 1, 2, 3]
    done = run(tmp_path, {1: front, 2: front, 3: front[:3]})  # median: the whole front, 25 %
    assert done.returncode == 0 and "met" in done.stdout, done.stdout + done.stderr
    done = run(tmp_path, {1: front + [4], 2: front + [5], 3: front + [6]})
    assert done.returncode == 1 and "missed" in done.stdout  # 5/16 = 31 % > 30 %
    done = run(tmp_path, {1: front[:3], 2: front[1:], 3: front[:2]})
    assert done.returncode == 1 and "missed" in done.stdout  # 25 % but never the whole front


def test_a_config_outside_the_grid_fails(tmp_path):
    done = run(tmp_path, {1: [0, 99]}, seeds="1")
    assert done.returncode == 2
    assert "config 99 is not in the grid" in done.stderr
