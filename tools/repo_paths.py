"""Paths in the records the tools write (a training's train.json, an experiment's
experiment.json and point.json): relative to the repository when they lie in it, so that a
committed record names no folder of the machine that wrote it, and absolute otherwise. A
relative path read back from a record is relative to the repository, wherever the tool runs."""
import os
import pathlib

ROOT = pathlib.Path(__file__).resolve().parent.parent


def recorded(path):
    """PATH as a record keeps it: repository-relative if it lies in the repository, else
    absolute; "" (and None) stay as they are."""
    if not path:
        return path
    for p in (os.path.abspath(path), os.path.realpath(path)):
        try:
            return str(pathlib.Path(p).relative_to(ROOT))
        except ValueError:
            continue
    return os.path.abspath(path)


def usable(path):
    """A path read from a record, absolute: a relative one is relative to the repository."""
    if not path:
        return path
    return str(path) if os.path.isabs(path) else str(ROOT / path)
