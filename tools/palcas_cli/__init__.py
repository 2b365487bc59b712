"""./palcas run, train, experiment and replay: one Python package (README.md beside this file).

`./palcas` installs, builds and dispatches; it runs `python3 tools/palcas_cli check COMMAND ...`
first (a bad option exits 2 before anything is installed or built), then builds and sources
the workspace if the command needs it, then `python3 tools/palcas_cli COMMAND ...`."""
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]  # the repository
TOOLS = ROOT / "tools"
# The tools the commands use as modules (palcas_arms, policy_folder, metrics_table, ...).
if str(TOOLS) not in sys.path:
    sys.path.insert(0, str(TOOLS))


class Console:
    """Where a command writes: results (its table, the console lines it shows) to `out`, its
    "[palcas] ..." lines to `err`. An experiment point gives both its point.log."""

    def __init__(self, out=None, err=None):
        self.out, self.err = out or sys.stdout, err or sys.stderr

    def log(self, text):
        self.err.write("[palcas] %s\n" % text)
        self.err.flush()

    def error(self, text):
        self.log("error: %s" % text)
