#!/usr/bin/env python3
"""The arm registry: config/arms.json, one entry per arm, read by ./palcas, the tools and
launch/system.launch alike. Adding an arm is adding its entry there.

An entry's fields:
  what              one line for help texts
  title             its name in tables and figures (config/paper_results.csv rows use the arm's key)
  rsus              zones (one RSU per zone: rsu_0, rsu_1, ...) | central (one RSU, central,
                    over the whole road) | none (no RSU: nothing learns)
  advice            where the RSUs' advice comes from: network (the learned policy: a learning
                    arm) | rules (the rule of config/rules.yaml: a control arm that learns
                    nothing) | none (no RSU)
  federation, i2i   the RSUs federate through the server / talk to their neighbours
  priority_reward   the reward's priority terms (false: lambda = 0)
  advisory_control  the bridge carries out advice (false: SUMO's own models for every vehicle)
  assist_mode       the bridge's assist_mode (advice on top of the CAVs' own lane changing)
  shipped_policy    policies/<arm>/ is this arm's shipped policy, bridge.yaml included (the
                    launch loads that bridge.yaml when it evaluates the shipped policy)
  bridge_params     an arm without a shipped policy: the bridge parameters it runs under, a
                    path under config/ ("" = none), so that a control arm drives its CAVs with
                    the same actuation as the learned arms' policies (their bridge.yaml)
  shipped_rsu_params  (optional, default false) the shipped policy carries RSU parameters it
                    runs under, policies/<arm>/rsu.yaml (the launch loads it after
                    config/departures.yaml when it evaluates the shipped policy; roslaunch cannot
                    ask whether a file exists, so the registry says it, and load() checks it)

JSON because roslaunch's $(eval) reads the same file as a Python literal (it has no YAML
parser); load() checks both readings agree.

usage: palcas_arms.py --list all|learning   the arm names, one a line
       palcas_arms.py --bash                 shell assignments ARMS, LEARNING_ARMS for ./palcas
       palcas_arms.py --help-text            an "arms:" section for ./palcas help"""
import json
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
REGISTRY = ROOT / "config" / "arms.json"
FIELDS = {"what": str, "title": str, "rsus": str, "federation": bool, "i2i": bool,
          "priority_reward": bool, "advisory_control": bool, "assist_mode": bool,
          "shipped_policy": bool, "advice": str, "bridge_params": str}
OPTIONAL_FIELDS = {"shipped_rsu_params": bool}
SHIPPED = ROOT / "policies"
RSU_RULES = ("zones", "central", "none")
ADVICE_SOURCES = ("network", "rules", "none")
# An arm's name becomes a launch argument, a folder name and part of experiment point names.
NAME = re.compile(r"^[a-z][a-z0-9_]*$")


class RegistryError(Exception):
    pass


def check(arms):
    """Refuses an entry that misses a field, has one of the wrong type, or contradicts itself."""
    if not isinstance(arms, dict) or not arms:
        raise RegistryError("the registry is not a mapping of arm names to entries")
    for name, entry in arms.items():
        if not NAME.match(name):
            raise RegistryError(f"arm '{name}': a name is lower-case letters, digits and _")
        if not isinstance(entry, dict) or not set(FIELDS) <= set(entry) <= set(FIELDS) | set(OPTIONAL_FIELDS):
            raise RegistryError(f"arm '{name}': fields {sorted(entry) if isinstance(entry, dict) else entry}, "
                                f"expected {sorted(FIELDS)} (and optionally {', '.join(sorted(OPTIONAL_FIELDS))})")
        for field, kind in {**FIELDS, **OPTIONAL_FIELDS}.items():
            if field in entry and type(entry[field]) is not kind:
                raise RegistryError(f"arm '{name}': {field} is not a {kind.__name__}")
        carries = entry.get("shipped_rsu_params", False)
        if carries and not entry["shipped_policy"]:
            raise RegistryError(f"arm '{name}': shipped_rsu_params needs a shipped policy")
        if entry["shipped_policy"] and carries != (SHIPPED / name / "rsu.yaml").is_file():
            raise RegistryError(f"arm '{name}': shipped_rsu_params is {str(carries).lower()} but policies/{name}/rsu.yaml "
                                + ("does not exist" if carries else "exists (the launch would not load it)"))
        if entry["rsus"] not in RSU_RULES:
            raise RegistryError(f"arm '{name}': rsus '{entry['rsus']}' is not one of {', '.join(RSU_RULES)}")
        if entry["rsus"] != "zones" and (entry["federation"] or entry["i2i"]):
            raise RegistryError(f"arm '{name}': federation and i2i need RSUs per zone")
        if entry["rsus"] == "none" and (entry["priority_reward"] or entry["shipped_policy"]):
            raise RegistryError(f"arm '{name}': without RSUs there is no reward and no policy")
        if entry["assist_mode"] and not entry["advisory_control"]:
            raise RegistryError(f"arm '{name}': assist_mode needs advisory_control")
        if entry["advice"] not in ADVICE_SOURCES:
            raise RegistryError(f"arm '{name}': advice '{entry['advice']}' is not one of {', '.join(ADVICE_SOURCES)}")
        if (entry["rsus"] == "none") != (entry["advice"] == "none"):
            raise RegistryError(f"arm '{name}': advice '{entry['advice']}' with rsus '{entry['rsus']}' "
                                "(RSUs advise by network or rules; without RSUs there is no advice)")
        if entry["advice"] == "rules" and (entry["federation"] or entry["priority_reward"] or entry["shipped_policy"]):
            raise RegistryError(f"arm '{name}': a rule learns nothing: no federation, reward or shipped policy")
        if entry["bridge_params"]:
            if entry["shipped_policy"]:
                raise RegistryError(f"arm '{name}': a shipped policy carries its own bridge.yaml; bridge_params must be ''")
            if not entry["advisory_control"]:
                raise RegistryError(f"arm '{name}': bridge_params without advisory_control change nothing the arm runs")
            if not (ROOT / "config" / entry["bridge_params"]).is_file():
                raise RegistryError(f"arm '{name}': bridge_params '{entry['bridge_params']}' is not a file under config/")
    return arms


def load(path=REGISTRY):
    text = pathlib.Path(path).read_text()
    arms = json.loads(text)
    # What system.launch reads: the text as a Python literal with true/false defined.
    try:
        as_launch_reads = eval(text, {"__builtins__": {}}, {"true": True, "false": False})  # noqa: S307
    except (NameError, SyntaxError) as e:
        raise RegistryError(f"{path}: roslaunch cannot read it as a Python literal ({e})")
    if as_launch_reads != arms:
        raise RegistryError(f"{path}: read as a Python literal it differs from its JSON (roslaunch reads it so)")
    return check(arms)


ARMS = load()
ALL_ARMS = tuple(ARMS)
LEARNING_ARMS = tuple(a for a in ARMS if ARMS[a]["advice"] == "network")
# Arms whose CAVs are driven by something other than a learned policy: the trial's controls.
CONTROL_ARMS = tuple(a for a in ARMS if ARMS[a]["advice"] != "network")


def is_learning(arm):
    return arm in LEARNING_ARMS


def title(arm):
    """The arm's name in tables and figures (an unknown one: itself)."""
    return ARMS[arm]["title"] if arm in ARMS else arm


def rsu_ids(arm, clusters):
    """The RSUs an arm runs on a road with this many zones."""
    rule = ARMS[arm]["rsus"]
    return ["central"] if rule == "central" else ["rsu_%d" % k for k in range(clusters)] if rule == "zones" else []


def sort_arms(arms):
    """Registry order; arms it does not know last, by name."""
    return sorted(arms, key=lambda a: (ALL_ARMS.index(a) if a in ARMS else len(ALL_ARMS), a))


def help_text():
    width = max(len(a) for a in ALL_ARMS)
    lines = ["arms (config/arms.json; a learning arm's shipped policy is policies/<arm>/):"]
    for a in ALL_ARMS:
        kind = {"network": "learning", "rules": "rule    "}.get(ARMS[a]["advice"], "no RSU  ")
        lines.append(f"  {a:<{width}}  {kind}  {ARMS[a]['what']}")
    return "\n".join(lines)


def main(argv):
    if argv == ["--list", "all"]:
        print("\n".join(ALL_ARMS))
    elif argv == ["--list", "learning"]:
        print("\n".join(LEARNING_ARMS))
    elif argv == ["--bash"]:
        print(f"ARMS='{' '.join(ALL_ARMS)}'")
        print(f"LEARNING_ARMS='{' '.join(LEARNING_ARMS)}'")
    elif argv == ["--help-text"]:
        print(help_text())
    else:
        sys.exit(__doc__.split("\n\n")[-1])


if __name__ == "__main__":
    main(sys.argv[1:])
