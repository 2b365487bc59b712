"""python3 tools/palcas_cli [check] run|train|experiment|replay ARGS... (./palcas runs it)."""
import os
import sys

# This folder is sys.path[0] when Python runs it by path: put tools/ there instead, so that
# `palcas_cli` is the package and its modules' names (run, train, ...) shadow nothing.
sys.path[0] = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

from palcas_cli.commands import main  # noqa: E402

sys.exit(main(sys.argv[1:]))
