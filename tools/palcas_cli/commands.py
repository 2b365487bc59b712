"""The commands and their dispatch: `python3 tools/palcas_cli COMMAND ARGS...` runs one,
`python3 tools/palcas_cli check COMMAND ARGS...` only checks its options (what ./palcas does
before it installs or builds anything)."""
import importlib
import sys

from palcas_cli.options import OptionError

COMMANDS = ("run", "train", "experiment", "replay")  # modules of this package
# Exit status of `check`: the options are good and the command needs the built, sourced
# workspace (BUILD) or nothing at all (NO_BUILD: planning or collecting an experiment).
BUILD, NO_BUILD, BAD_OPTION = 0, 3, 2
USAGE = "usage: palcas_cli [check] %s ARGS... (see ./palcas help)" % "|".join(COMMANDS)


def check(command, argv):
    module = importlib.import_module("palcas_cli." + command)
    try:
        needs_workspace = module.needs_workspace(argv) if hasattr(module, "needs_workspace") else bool(
            module.check(argv) or True)
    except SystemExit as e:  # --help: printed, nothing to build
        return NO_BUILD if e.code in (0, None) else BAD_OPTION
    return BUILD if needs_workspace else NO_BUILD


def main(argv):
    checking = argv[:1] == ["check"]
    words = argv[1:] if checking else argv
    if not words or words[0] not in COMMANDS:
        print(USAGE, file=sys.stderr)
        return BAD_OPTION
    try:
        if checking:
            return check(words[0], words[1:])
        return importlib.import_module("palcas_cli." + words[0]).main(words[1:])
    except OptionError as e:
        print("%s error: %s" % (e.prefix, e), file=sys.stderr)
        return BAD_OPTION
