#!/usr/bin/env python3
"""The named evaluation seed sets of config/seeds.yaml: dev (settings are chosen on it) and
test (results are reported on it, never tuned on). See that file's comment for the rule.

  load()              {name: [seed, ...]} in the file's order, checked (integers, no seed
                      twice, no seed in two sets)
  seeds(name, n)      the first n seeds of the set; SeedSetError naming the set and its size
                      when n is too large, or the known sets when the name is unknown

usage: seed_sets.py NAME [N]     the set's (first N) seeds, comma-separated"""
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
SEEDS_FILE = ROOT / "config" / "seeds.yaml"
DEFAULT = "test"


class SeedSetError(ValueError):
    pass


def load(path=SEEDS_FILE):
    import yaml
    path = pathlib.Path(path)
    try:
        data = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError) as e:
        raise SeedSetError(f"{path}: cannot read the seed sets ({e})")
    if not isinstance(data, dict) or not data:
        raise SeedSetError(f"{path}: not a mapping of set names to seed lists")
    owner = {}
    sets = {}
    for name, seeds in data.items():
        if not isinstance(seeds, list) or not seeds:
            raise SeedSetError(f"{path}: set '{name}' is not a non-empty list of seeds")
        for s in seeds:
            if type(s) is not int or s < 0:
                raise SeedSetError(f"{path}: set '{name}': {s!r} is not a seed (an integer >= 0)")
            if s in owner:
                where = "twice" if owner[s] == name else f"also in set '{owner[s]}'"
                raise SeedSetError(f"{path}: set '{name}': seed {s} is {where}")
            owner[s] = name
        sets[str(name)] = list(seeds)
    return sets


def describe(seeds):
    """'101-130' for a run of consecutive seeds, else '101, 105, ...'."""
    if seeds == list(range(seeds[0], seeds[0] + len(seeds))) and len(seeds) > 2:
        return f"{seeds[0]}-{seeds[-1]}"
    return ", ".join(str(s) for s in seeds)


def seeds(name, n, path=SEEDS_FILE):
    """The first n seeds of set `name`."""
    sets = load(path)
    if name not in sets:
        raise SeedSetError(f"unknown seed set '{name}' (config/seeds.yaml has {', '.join(sets)})")
    have = sets[name]
    if type(n) is not int or n < 1:
        raise SeedSetError(f"seed set '{name}': {n!r} seeds asked, at least 1 needed")
    if n > len(have):
        raise SeedSetError(f"seed set '{name}' has {len(have)} seeds ({describe(have)}), "
                           f"not {n}: use fewer, or add seeds to it in config/seeds.yaml")
    return have[:n]


def set_of(seed_list, path=SEEDS_FILE):
    """The name of the set holding every seed of seed_list, else None."""
    for name, have in load(path).items():
        if seed_list and set(seed_list) <= set(have):
            return name
    return None


def main(argv):
    if not 1 <= len(argv) <= 2:
        sys.exit(__doc__.split("\n\n")[-1])
    try:
        name = argv[0]
        n = int(argv[1]) if len(argv) == 2 else len(load().get(name, [])) or 1
        print(",".join(str(s) for s in seeds(name, n)))
    except (SeedSetError, ValueError) as e:
        sys.exit(f"seed_sets: {e}")


if __name__ == "__main__":
    main(sys.argv[1:])
