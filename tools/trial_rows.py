#!/usr/bin/env python3
"""Add an experiment's points to the trial's rows under another arm name.

  /usr/bin/python3 tools/trial_rows.py --arm palcas --as palcas_quarter_s201 \\
      --out docs/trial/results_quarter_trainings.csv EXP/results.csv [EXP2/results.csv ...]

A learned arm evaluated with another policy (`./palcas experiment --arms palcas --policy
palcas=DIR`) writes its rows as `palcas`; on the results page they must be their own arm. This
takes the rows of --arm from each results.csv of ./palcas experiment, names them --as (the arm
column and the point's name), and appends them to --out (created with the inputs' header).
Refused, with nothing written: an input without the arm's rows, inputs whose columns differ
from each other or from --out's, a point already in --out or twice in the inputs, a row that did
not finish (status other than done) unless --keep-failed, and --as naming an arm of the
registry (config/arms.json: its rows would be read as that arm's)."""
import argparse
import csv
import json
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent


class RowsError(Exception):
    pass


def read_csv(path):
    try:
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            rows = list(reader)
            return list(reader.fieldnames or []), rows
    except OSError as e:
        raise RowsError(f"{path}: {e.strerror}")


def renamed(rows, arm, new, path, keep_failed):
    out = []
    for r in rows:
        if r.get("arm") != arm:
            continue
        if r.get("status") != "done" and not keep_failed:
            raise RowsError(f"{path}: point {r.get('point')} did not finish ({r.get('status')}); "
                            f"run it again, or --keep-failed to record it as it is")
        point = r.get("point") or ""
        if not point.startswith(arm + "_"):
            raise RowsError(f"{path}: point {point!r} is not named after its arm {arm!r}")
        out.append(dict(r, arm=new, point=new + point[len(arm):]))
    if not out:
        raise RowsError(f"{path}: no row of arm {arm!r}")
    return out


def add_rows(arm, new, inputs, out, keep_failed=False, registry=None):
    """The rows appended to `out` (a list of dicts); raises RowsError before writing anything."""
    registry = registry if registry is not None else json.loads((ROOT / "config" / "arms.json").read_text())
    if new == arm:
        raise RowsError(f"--as {new}: the same name as --arm")
    if new in registry:
        raise RowsError(f"--as {new}: an arm of config/arms.json; its rows would be read as that arm's")
    head, added = None, []
    for path in inputs:
        fields, rows = read_csv(path)
        if head is None:
            head = fields
        elif fields != head:
            raise RowsError(f"{path}: its columns differ from {inputs[0]}'s")
        added += renamed(rows, arm, new, path, keep_failed)
    out = pathlib.Path(out)
    have = []
    if out.exists():
        fields, have = read_csv(out)
        if fields != head:
            raise RowsError(f"{out}: its columns differ from the inputs'")
    seen = {r["point"] for r in have}
    for r in added:
        if r["point"] in seen:
            raise RowsError(f"point {r['point']} is already in {out} or twice in the inputs")
        seen.add(r["point"])
    new_file = not out.exists()
    with open(out, "a", newline="") as f:
        w = csv.DictWriter(f, fieldnames=head, lineterminator="\n")
        if new_file:
            w.writeheader()
        w.writerows(added)
    return added


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--arm", required=True, help="the arm whose rows to take (e.g. palcas)")
    ap.add_argument("--as", dest="new", required=True, help="the name they get on the page")
    ap.add_argument("--out", required=True, help="the trial's CSV to append to (created if missing)")
    ap.add_argument("--keep-failed", action="store_true", help="record points that did not finish as they are")
    ap.add_argument("inputs", nargs="+", help="results.csv files of ./palcas experiment")
    a = ap.parse_args(argv)
    try:
        added = add_rows(a.arm, a.new, a.inputs, a.out, a.keep_failed)
    except RowsError as e:
        print(f"trial_rows: {e}", file=sys.stderr)
        return 2
    print(f"trial_rows: {len(added)} rows of {a.arm} added to {a.out} as {a.new}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
