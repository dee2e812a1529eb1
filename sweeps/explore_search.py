#!/usr/bin/python3
"""The Optuna side of `sfx explore`: asks an Optuna study for configurations to evaluate and
tells it what they scored. sfx evaluates them (engines, results store); this never runs one.

Each call is one short process (stdin: one JSON request, stdout: one JSON answer), and the
study lives in an SQLite file, so a killed explore resumes from the file: trials asked and
never told (RUNNING) are handed out again first, and the sampler is re-seeded from the seed
and the number of trials so far, so the same file and seed give the same sequence.

request:  {"storage": PATH, "study": NAME,
           "space": [{"name": "hw.simd.width", "values": ["4", "8"], "ordinal": true}, ...],
           "directions": ["maximize", "minimize", ...], "sampler": "tpe" | "nsga2" | "random",
           "seed": 1, "batch": 8, "startup": 10, "fingerprint": "...",
           "results": [{"number": 3, "values": [...], "constraints": [...]},
                       {"number": 4, "failed": true}],     told first (may be empty)
           "n": 8}                                          then asked for (may be 0)
answer:   {"told": 2, "trials": [{"number": 5, "params": {"hw.simd.width": 1, ...}, "resumed": false}]}
          (params are indices into each knob's values; resumed: asked before, never told)
An explore whose file changed its space under the same name is refused (exit 2): its trials
would not mean the same configurations.
"""

import json
import sys

import warnings

import optuna

# One line per trial would bury sfx's progress; errors still reach stderr. The TPE options used
# here are marked experimental in Optuna 3.1 (Debian 12's), which is the version pinned.
optuna.logging.set_verbosity(optuna.logging.WARNING)
warnings.filterwarnings("ignore", category=optuna.exceptions.ExperimentalWarning)

CONSTRAINTS_ATTR = "sfx_constraints"


def constraints_of(trial):
    """Optuna's constraints: <= 0 is feasible (sfx scales each by its bound)."""
    return trial.user_attrs.get(CONSTRAINTS_ATTR, [])


def make_sampler(req, trials_so_far):
    # Re-seeded per call from the count so far: each call is a new process, and the same seed
    # would otherwise replay the same draws.
    seed = int(req["seed"]) * 100003 + trials_so_far
    if req["sampler"] == "random":  # the baseline a search must beat
        return optuna.samplers.RandomSampler(seed=seed)
    if req["sampler"] == "nsga2":
        return optuna.samplers.NSGAIISampler(
            population_size=max(2, int(req["batch"])), seed=seed, constraints_func=constraints_of)
    # TPE (multi-objective since Optuna 3.0); the constant liar spreads a batch's asks apart.
    return optuna.samplers.TPESampler(
        n_startup_trials=int(req["startup"]), seed=seed, multivariate=True,
        constant_liar=True, constraints_func=constraints_of, warn_independent_sampling=False)


def open_study(req):
    storage = optuna.storages.RDBStorage("sqlite:///" + req["storage"])
    study = optuna.create_study(storage=storage, study_name=req["study"],
                                directions=req["directions"], load_if_exists=True)
    fingerprint = study.user_attrs.get("sfx_fingerprint")
    if fingerprint is None:
        study.set_user_attr("sfx_fingerprint", req["fingerprint"])
    elif fingerprint != req["fingerprint"]:
        sys.stderr.write(
            f"{req['storage']}: study '{req['study']}' was made for another space, objectives or "
            "sampler (the explore file changed); rename the explore (name:) or delete the study file\n")
        sys.exit(2)
    study.sampler = make_sampler(req, len(study.trials))
    return study


def distributions(space):
    out = {}
    for knob in space:
        n = len(knob["values"])
        if knob["ordinal"]:
            out[knob["name"]] = optuna.distributions.IntDistribution(0, n - 1)
        else:
            out[knob["name"]] = optuna.distributions.CategoricalDistribution(list(knob["values"]))
    return out


def indices(space, params):
    out = {}
    for knob in space:
        v = params[knob["name"]]
        out[knob["name"]] = v if knob["ordinal"] else knob["values"].index(v)
    return out


def ask(study, req):
    dists = distributions(req["space"])
    trials = []
    for t in study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.RUNNING,)):
        trials.append({"number": t.number, "params": indices(req["space"], t.params), "resumed": True})
    while len(trials) < int(req.get("n", 0)):
        t = study.ask(dists)
        trials.append({"number": t.number, "params": indices(req["space"], t.params), "resumed": False})
    return trials


def tell(study, req):
    told = 0
    for r in req.get("results", []):
        frozen = study.get_trials(deepcopy=False)[int(r["number"])]
        if frozen.state != optuna.trial.TrialState.RUNNING:
            continue  # told before a kill: the answer is already in the study
        trial = optuna.trial.Trial(study, frozen._trial_id)
        if r.get("failed"):
            study.tell(trial, state=optuna.trial.TrialState.FAIL)
        else:
            trial.set_user_attr(CONSTRAINTS_ATTR, [float(c) for c in r["constraints"]])
            study.tell(trial, [float(v) for v in r["values"]])
        told += 1
    return told


def main():
    req = json.load(sys.stdin)
    study = open_study(req)
    told = tell(study, req)
    # A new sampler: the one open_study made was seeded before these trials were told.
    study.sampler = make_sampler(req, len(study.trials))
    answer = {"told": told, "trials": ask(study, req)}
    json.dump(answer, sys.stdout)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
