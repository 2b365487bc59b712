#!/usr/bin/env python3
"""Copies what a user needs of a ./palcas train folder into policies/<arm>/: the
global model, the training record and its curves; not the replay-laden checkpoints.

usage: ship_policy.py [--rsu-models] [--default-from RSU] [--bridge-as-trained | --run-with-bridge FILE] [--run-with-rsu FILE] TRAIN_DIR DEST_DIR

--rsu-models: ship each RSU's own final model (checkpoints/<rsu>/model.palcas: the last
global model it loaded plus its local steps since) instead of the server's global model, and
the global model as checkpoints/default/model.palcas: the model an RSU of a zone the training
did not have (a road with more clusters) starts from. --default-from RSU: without a global
model (independent, centralized), that RSU's model is the default one.
--bridge-as-trained: the policy runs under the bridge parameters it was trained with: the
training's --bridge-params file is copied as DEST_DIR/bridge.yaml, which `./palcas run`
loads for the policy's arm (after config/bridge.yaml, before a --bridge-params of its own).
--run-with-bridge FILE: the policy runs under FILE's bridge parameters (copied as
bridge.yaml) although it was not trained under them; TRAINING.md says so.
Without either a policy runs under config/bridge.yaml, whatever it was trained under.
--run-with-rsu FILE: the policy's RSUs run under FILE's parameters (copied as rsu.yaml;
`./palcas run` loads it after config/departures.yaml, before a --rsu-params of its own);
TRAINING.md says so. A shipped policy with one needs its arm's shipped_rsu_params in
config/arms.json (the launch reads the registry, not the folder).

DEST_DIR then is itself a policy folder for `./palcas run --policy` (train.json,
checkpoints/fedserver/global_model.palcas or checkpoints/<rsu>/model.palcas) and carries
TRAINING.md: command, commit, wall time, simulated hours, seeds, episodes."""
import csv
import filecmp
import json
import pathlib
import shutil
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import policy_folder as pf  # noqa: E402
import repo_paths  # noqa: E402


def bridge_line(trained_with, runs_with, as_trained):
    """TRAINING.md's line on the bridge parameters the policy runs under."""
    trained = (f"`{pathlib.Path(trained_with).name}` over " if trained_with else "") + "config/bridge.yaml"
    if as_trained:
        return "- runs under the bridge parameters it was trained with: `bridge.yaml` (over config/bridge.yaml)"
    if runs_with:
        return ("- runs under the bridge parameters in `bridge.yaml` (over config/bridge.yaml), which its "
                f"training did not use (trained under {trained})")
    return "- runs under config/bridge.yaml (trained under " + (
        f"`{pathlib.Path(trained_with).name}` over it" if trained_with else "it") + ")"


def rsu_line(runs_with, trained_with):
    """TRAINING.md's line on the RSU parameters the policy runs under (its rsu.yaml)."""
    head = f"- its RSUs run under the parameters in `{pf.RSU_PARAMS}` (over config/departures.yaml)"
    if trained_with and filecmp.cmp(runs_with, trained_with, shallow=False):
        return f"{head}, the ones its training used (`{pathlib.Path(runs_with).name}`)"
    trained = f"trained under `{pathlib.Path(trained_with).name}`" if trained_with else "trained without one"
    return f"{head}, which its training did not use (`{pathlib.Path(runs_with).name}`; {trained})"


def traffic_text(train):
    """The training's PR and demand as train.json holds them: fixed, or drawn per episode."""
    def span(r):
        return f"{r[0]:g}-{r[1]:g}"
    pr = f"PR drawn per episode from {span(train['pr_range'])} %" if train.get("pr_range") else f"PR {train['pr']} %"
    if train.get("demand_range"):
        demand = f"mainline demand drawn per episode from {span(train['demand_range'])} veh/h/lane"
    elif train.get("demand_vphpl") is not None:
        demand = f"mainline demand {train['demand_vphpl']:g} veh/h/lane"
    else:
        demand = "the scenario's demand"
    return f"{pr}, {demand}" + (f", V2X channel `{train['v2x_params']}`" if train.get("v2x_params") else "")


def main(train_dir, dest, rsu_models=False, bridge_as_trained=False, run_bridge=None, default_from=None,
         run_rsu=None):
    src = pathlib.Path(train_dir).resolve()
    dst = pathlib.Path(dest)
    train = pf.train_record(src)
    # The record's files, usable here (a relative one is relative to the repository); the
    # shipped record keeps them repository-relative (tools/repo_paths.py).
    for key in ("rsu_params", "bridge_params", "v2x_params"):
        if train.get(key):
            train[key] = repo_paths.recorded(repo_paths.usable(train[key]))
    bridge = repo_paths.usable(train.get("bridge_params", ""))
    if bridge_as_trained and not bridge:
        sys.exit(f"--bridge-as-trained: {src} was trained under config/bridge.yaml alone "
                 "(no --bridge-params); nothing to carry")
    if bridge_as_trained and not pathlib.Path(bridge).is_file():
        sys.exit(f"--bridge-as-trained: the training's bridge parameters {bridge} are gone")
    if run_bridge and not pathlib.Path(run_bridge).is_file():
        sys.exit(f"--run-with-bridge: no such file {run_bridge}")
    if run_rsu and not pathlib.Path(run_rsu).is_file():
        sys.exit(f"--run-with-rsu: no such file {run_rsu}")
    if default_from and not pf.rsu_model(src, default_from).is_file():
        sys.exit(f"--default-from: {src} holds no checkpoints/{default_from}/model.palcas")
    learning = repo_paths.usable(train.get("learning", ""))
    if learning and not pathlib.Path(learning).is_file():
        # The training writes its schedule into its own folder and records it relative to the
        # repository it ran in: from another checkout (a worktree), take the folder's copy.
        own = src / pathlib.Path(learning).name
        if not own.is_file():
            sys.exit(f"the training's learning parameters {learning} are gone (nor in {src})")
        learning = str(own)
    run_bridge = run_bridge or (bridge if bridge_as_trained else None)
    if dst.exists():
        shutil.rmtree(dst)
    pf.checkpoints(dst).mkdir(parents=True)
    global_model = pf.global_model(src)
    state = pf.federation_state(src)
    if state.exists():  # the rounds the training closed (reported beside evaluations)
        pf.federation_state(dst).parent.mkdir()
        shutil.copy2(state, pf.federation_state(dst))
    if global_model.exists() and not rsu_models:  # federated arms: the server's global model
        pf.global_model(dst).parent.mkdir(exist_ok=True)
        shutil.copy2(global_model, pf.global_model(dst))
    else:  # independent / centralized, or --rsu-models: one model per RSU
        for model in pf.rsu_models(src):
            pf.rsu_model(dst, model.parent.name).parent.mkdir()
            shutil.copy2(model, pf.rsu_model(dst, model.parent.name))
        default = global_model if global_model.exists() else (
            pf.rsu_model(src, default_from) if default_from else None)
        if default:  # for RSUs without a model of their own (palcas_rsu: the load order)
            pf.rsu_model(dst, pf.DEFAULT_RSU).parent.mkdir(exist_ok=True)
            shutil.copy2(default, pf.rsu_model(dst, pf.DEFAULT_RSU))
            train["default_model"] = "global" if default == global_model else default_from
    for csv_file in pf.learning_logs(src):
        (pf.checkpoints(dst) / csv_file.parent.name).mkdir(exist_ok=True)
        shutil.copy2(csv_file, pf.checkpoints(dst) / csv_file.parent.name)
    for f in pf.RECORD_FILES:
        if (src / f).exists():
            shutil.copy2(src / f, dst / f)
    if learning:  # the override travels with the policy, referred to by its file name
        shutil.copy2(learning, dst / pathlib.Path(learning).name)
        train["learning"] = pathlib.Path(learning).name
    if run_bridge:
        shutil.copy2(run_bridge, pf.bridge_params(dst))
        train["runs_with_bridge"] = pf.BRIDGE_PARAMS
    if run_rsu:
        shutil.copy2(run_rsu, pf.rsu_params(dst))
        train["runs_with_rsu"] = pf.RSU_PARAMS
    train["shipped_from"] = src.name
    train["shipped_models"] = "rsu" if rsu_models or not global_model.exists() else "global"
    pf.train_record_path(dst).write_text(json.dumps(train) + "\n")

    rows = list(csv.DictReader(open(src / pf.EPISODES)))
    sim_s = sum(float(r["sim_seconds"]) for r in rows)
    wall_s = sum(float(r["wall_seconds"]) for r in rows)
    seeds = [int(r["seed"]) for r in rows]
    aborted = (src / "aborted_episodes.txt").read_text().splitlines() if (src / "aborted_episodes.txt").exists() else []
    manifest = json.loads((src / "manifest.json").read_text()) if (src / "manifest.json").exists() else {}
    lines = [
        f"# Training record of this policy ({train['arm']})",
        "",
        f"- command: `{train.get('command_line') or manifest.get('command_line', '(unknown)')}`"
        + "".join(f", continued with `{c}`" for c in train.get("resumed_with", [])),
        f"- road {train['scenario']}, {traffic_text(train)}, {train['episodes']} x {train['duration_s']:.0f} s, "
        f"exploration over {100 * float(train.get('explore_fraction', 0.5)):.0f} % of the budget"
        + (", paper as printed" if train.get("paper_printed") else ", config/departures.yaml"),
        f"- commit: `{manifest.get('git_commit') or train.get('git_commit', 'unknown')}`",
        f"- episodes completed: {len(rows)} of {train['episodes']} (training seeds {min(seeds)}..{max(seeds)}; "
        f"evaluate on other seeds, e.g. 101-103)",
        f"- simulated: {sim_s / 3600:.2f} h; wall time inside the simulations: {wall_s / 60:.1f} min "
        f"(real-time factor {sim_s / wall_s:.1f}x)",
        f"- episodes ended early and not counted: {len(aborted)}" + ("".join("\n  - " + a for a in aborted)),
        ("- models: each RSU's own final model, `checkpoints/<rsu>/model.palcas` (its zone's RSU loads it)"
         + ("; an RSU without one loads `checkpoints/default/model.palcas` ("
            + ("the federation's final global model; `--rsu-params config/global_model.yaml` runs it on every RSU"
               if train.get("default_model") == "global"
               else f"{train.get('default_model')}'s model") + ")"
            if train.get("default_model") else "; an RSU without one has no model to load")
         if train["shipped_models"] == "rsu" else
         "- model: `checkpoints/fedserver/global_model.palcas` (the model every RSU loads)"),
        bridge_line(bridge, run_bridge, bridge_as_trained),
        *([rsu_line(run_rsu, repo_paths.usable(train.get("rsu_params", "")))] if run_rsu else []),
        "- files: "
        "`episodes.csv` (per-episode metrics), `learning_curves.png` / `.csv`, "
        "`checkpoints/<rsu>/learning.csv` (per-RSU learning rows)",
    ]
    (dst / pf.TRAINING_NOTES).write_text("\n".join(lines) + "\n")
    print(f"shipped {src} -> {dst}")


if __name__ == "__main__":
    import argparse
    ap = argparse.ArgumentParser(usage=__doc__.split("\n\n")[1])
    ap.add_argument("--rsu-models", action="store_true")
    ap.add_argument("--default-from", metavar="RSU")
    which = ap.add_mutually_exclusive_group()
    which.add_argument("--bridge-as-trained", action="store_true")
    which.add_argument("--run-with-bridge", metavar="FILE")
    ap.add_argument("--run-with-rsu", metavar="FILE")
    ap.add_argument("train_dir")
    ap.add_argument("dest_dir")
    a = ap.parse_args()
    main(a.train_dir, a.dest_dir, rsu_models=a.rsu_models, bridge_as_trained=a.bridge_as_trained,
         run_bridge=a.run_with_bridge, default_from=a.default_from, run_rsu=a.run_with_rsu)
