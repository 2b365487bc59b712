"""Option values of run, train, experiment and replay, checked before anything is installed,
built or created. Each checker returns the value in normal form or raises OptionError
naming the option and the value (`./palcas` exits 2 with it). Standard library only, plus
PyYAML for the few checks that read a road's scenario.yaml (imported where needed)."""
import argparse
import os
import pathlib
import re

from palcas_cli import ROOT
import palcas_arms
import policy_folder

SCENARIOS = ROOT / "config" / "scenarios"
# Demand bounds [veh/h per lane]: what the bridge accepts (~scenario/*_flow_vphpl).
MAX_DEMAND = 100000
# RSU r seeds its agent with seed * 1000 + r, a 32-bit ROS parameter.
MAX_SEED = 2147482
# SUMO's outputs by name: the names palcas_sim/sumo_outputs.cpp knows (sumo_outputs_test
# checks the two lists agree).
SUMO_OUTPUTS = ("fcd", "tripinfo", "ssm", "lanechange", "collision", "summary", "statistic")
# A plain decimal: no sign, no exponent (what a user types for a duration, PR or demand).
DECIMAL = re.compile(r"^([0-9]+\.?[0-9]*|\.[0-9]+)$")


class OptionError(Exception):
    """A bad command line: exit 2, before anything is installed, built or created."""
    prefix = "[palcas]"  # how the message starts: "[palcas] error: ..."


def normal(value):
    """A number as the launch and the folder names take it: 60, 0.5, 1200 (10 digits)."""
    return "%.10g" % float(value)


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """The description as written; each option's help wrapped beside it."""

    def __init__(self, prog):
        super().__init__(prog, max_help_position=32, width=100)


class Parser(argparse.ArgumentParser):
    """argparse for every command: --help lists each option with its default and exits 0,
    --x=y works, and a bad command line is an OptionError (exit 2, "[palcas] error: ...")
    instead of argparse's own message and exit."""

    def __init__(self, command, description=None):
        super().__init__(prog="./palcas " + command, description=description, allow_abbrev=False,
                         formatter_class=HelpFormatter)
        self.command = command

    def error(self, message):
        needs = re.match(r"argument (--[A-Za-z0-9-]+)(/\S+)?: expected one argument$", message)
        if needs:
            raise OptionError("option %s needs a value" % needs.group(1))
        raise OptionError("%s: %s (see ./palcas %s --help)" % (self.command, message, self.command))

    def unknown(self, word):
        raise OptionError("%s: unknown option '%s' (see ./palcas %s --help)" % (self.command, word, self.command))


def with_default(text, default):
    """An option's help: what it does, then its default (argparse's %-escapes kept)."""
    return "%s (default: %s)" % (text, default)


def parser(command, values, flags=None, joined=(), helps=None, description=None, positional=None):
    """The argparse parser of a command: VALUES maps an option to the key its value goes to,
    FLAGS an option to (key, value); a JOINED key collects its values; HELPS maps an option
    to (METAVAR, help with its default) (a flag's METAVAR is None). Nothing has an argparse
    default, so parsing gives only what was given; POSITIONAL (a name) takes the words that
    are no option."""
    ap, flags, helps = Parser(command, description), flags or {}, helps or {}
    if positional:
        ap.add_argument("words", nargs="?", metavar=positional, help=helps.get(positional, (None, ""))[1])
    # --help lists the options in HELPS's order, then any it does not describe.
    for option in [o for o in helps if o in values or o in flags] + [
            o for o in list(values) + list(flags) if o not in helps]:
        if option in values:
            key = values[option]
            metavar, text = helps.get(option, (key.upper(), ""))
            ap.add_argument(option, dest=key, metavar=metavar, help=text, default=argparse.SUPPRESS,
                            action="append" if key in joined else "store")
        else:
            key, value = flags[option]
            ap.add_argument(option, dest=key, action="store_const", const=value, default=argparse.SUPPRESS,
                            help=helps.get(option, (None, ""))[1])
    return ap


def parse(command, argv, values, flags=None, joined=(), positional=None, helps=None, description=None,
          positional_name="WORD"):
    """The options of a command line (parser() says what the tables hold): returns {key: value}
    of what was given; a JOINED key's values come comma-separated (else the last one counts); a
    word that is no option goes to positional(word), if the command takes one (shown in --help
    as POSITIONAL_NAME). --help prints the options with their defaults and exits 0 (SystemExit)."""
    ap = parser(command, values, flags, joined, helps, description, positional_name if positional else None)
    known, extra = ap.parse_known_args(list(argv))
    given = vars(known)
    words = [given.pop("words")] if given.get("words") is not None else []
    given.pop("words", None)
    for word in extra:  # words after the first option's value, and unknown options
        if positional and not word.startswith("-"):
            words.append(word)
        else:
            ap.unknown(word)
    for key in joined:
        if key in given:
            given[key] = ",".join(given[key])
    for word in words:
        if not positional:
            ap.unknown(word)
        positional(word)
    return given


def number_in(option, value, low, high, open_low=False):
    """A decimal in [low, high] ((low, high] with open_low; high None = no upper bound)."""
    text = ("in (%s, %s]" if open_low else "in [%s, %s]") % (low, high)
    if high is None:
        text = "greater than %s" % low
    if DECIMAL.match(value):
        v = float(value)
        if (v > float(low) if open_low else v >= float(low)) and (high is None or v <= float(high)):
            return normal(v)
    raise OptionError("%s '%s': expected a number %s" % (option, value, text))


def integer_in(option, value, low, high=None):
    """An integer in [low, high] (high None = no upper bound)."""
    if re.match(r"^[0-9]{1,12}$", value) and int(value) >= low and (high is None or int(value) <= high):
        return int(value)
    if high is None:
        raise OptionError("%s '%s': expected an integer >= %d" % (option, value, low))
    raise OptionError("%s '%s': expected an integer in [%d, %d]" % (option, value, low, high))


def range_in(option, value, low, high):
    """MIN,MAX: two numbers in [low, high], MIN <= MAX; returns "MIN,MAX" in normal form."""
    if not re.match(r"^[^,]+,[^,]+$", value):
        raise OptionError("%s '%s': expected MIN,MAX (two numbers in [%s, %s])" % (option, value, low, high))
    first, second = value.split(",")
    lo = number_in("%s '%s': MIN" % (option, value), first, low, high)
    hi = number_in("%s '%s': MAX" % (option, value), second, low, high)
    if float(lo) > float(hi):
        raise OptionError("%s '%s': MIN %s is greater than MAX %s" % (option, value, lo, hi))
    return "%s,%s" % (lo, hi)


def scenario_ok(option, name):
    """A road folder under config/scenarios, or an absolute path to a folder with scenario.yaml."""
    if name.startswith("/"):
        if os.path.isfile(os.path.join(name, "scenario.yaml")):
            return name
        raise OptionError("%s '%s': no scenario.yaml in that folder" % (option, name))
    if re.match(r"^[A-Za-z0-9_][A-Za-z0-9_.-]*$", name) and (SCENARIOS / name / "scenario.yaml").is_file():
        return name
    known = " ".join(sorted(p.parent.name for p in SCENARIOS.glob("*/scenario.yaml")))
    raise OptionError("%s '%s': no such road under config/scenarios (%s), nor an absolute path to a "
                      "folder with scenario.yaml" % (option, name, known))


def scenario_yaml(name):
    """The scenario.yaml of a road name or absolute folder."""
    return pathlib.Path(name) / "scenario.yaml" if name.startswith("/") else SCENARIOS / name / "scenario.yaml"


def scenario_description(name):
    import yaml
    return yaml.safe_load(scenario_yaml(name).read_text())


def scenario_state_size(name):
    """40 + the road's lane count: the feature count of a policy's networks on that road."""
    return 40 + int(scenario_description(name)["road"]["num_lanes"])


def scenario_demand(name):
    """The road's own mainline demand [veh/h per lane], as %g."""
    return "%g" % float(scenario_description(name)["mainline_flow_vphpl"])


def file_ok(option, path):
    """An existing file; returns its absolute path."""
    if not os.path.isfile(path):
        raise OptionError("%s '%s': no such file" % (option, path))
    return os.path.abspath(path)


def out_ok(out):
    """--out: a folder, or nothing yet."""
    if out and os.path.exists(out) and not os.path.isdir(out):
        raise OptionError("--out '%s': exists and is not a folder" % out)
    return out


def sumo_outputs_ok(names):
    """Comma-separated SUMO output names; returns them as a YAML list ("[fcd, ssm]")."""
    parts = names.split(",")
    if parts and parts[-1] == "":  # "fcd," names fcd only
        parts.pop()
    chosen = []
    for name in parts:
        if name not in SUMO_OUTPUTS:
            raise OptionError("--sumo-output '%s': unknown SUMO output (known: %s)" % (name, " ".join(SUMO_OUTPUTS)))
        if name in chosen:
            raise OptionError("--sumo-output '%s': named twice" % name)
        chosen.append(name)
    if not chosen:
        raise OptionError("--sumo-output '%s': no output named" % names)
    return "[%s]" % ", ".join(chosen)


def arms_text(arms):
    """"a | b | c", for messages."""
    return " | ".join(arms)


def policy_ok(option, folder):
    """A policy folder (tools/policy_folder.py); returns its absolute path."""
    why = policy_folder.why_not(folder)
    if why:
        raise OptionError("%s '%s': %s" % (option, folder, why))
    return os.path.abspath(folder)


def train_field(folder, key):
    """A text field of a policy folder's train.json ("" if it has none)."""
    try:
        value = policy_folder.train_record(folder).get(key, "")
    except (OSError, ValueError):
        return ""
    return value if isinstance(value, str) else ""


def trained_paper_printed(folder):
    """The policy trained with every constant as the paper prints it."""
    try:
        return policy_folder.train_record(folder).get("paper_printed") is True
    except (OSError, ValueError):
        return False


def policy_learning(option, folder):
    """The "learning:" override a policy was trained with ("" = none): as recorded; a relative
    path is relative to the repository; a moved training folder falls back to its own copy."""
    learning = train_field(folder, "learning")
    if not learning:
        return ""
    if not learning.startswith("/"):
        learning = str(ROOT / learning)
    own_copy = os.path.join(folder, os.path.basename(learning))
    if not os.path.isfile(learning) and os.path.isfile(own_copy):
        learning = own_copy
    if not os.path.isfile(learning):
        raise OptionError("%s '%s': its learning override '%s' (train.json) is missing" % (option, folder, learning))
    return learning


def _params_yaml_ok(option, folder, path, what):
    if not path.exists():
        return
    try:
        import yaml
        doc = yaml.safe_load(path.read_text())
    except Exception:  # noqa: BLE001 - unreadable or not YAML: the same answer
        doc = None
    if not (isinstance(doc, dict) and doc):
        raise OptionError("%s '%s': its %s is not a YAML mapping of %s parameters" % (option, folder, path.name, what))


def bridge_yaml_ok(option, folder):
    """A policy folder's bridge.yaml, if it has one, is a mapping of bridge parameters."""
    _params_yaml_ok(option, folder, policy_folder.bridge_params(folder), "bridge")


def rsu_yaml_ok(option, folder):
    """A policy folder's rsu.yaml, if it has one, is a mapping of RSU parameters."""
    _params_yaml_ok(option, folder, policy_folder.rsu_params(folder), "RSU")


def known_arm(arm, listed):
    """ARM is in the registry; the message lists LISTED (all arms, or the learning ones)."""
    if arm not in palcas_arms.ALL_ARMS:
        raise OptionError("--arm '%s': unknown arm (%s)" % (arm, arms_text(listed)))
    return arm


def results_dir():
    """Where a run or training without --out goes."""
    return os.environ.get("PALCAS_RESULTS_DIR") or str(ROOT / "results")
