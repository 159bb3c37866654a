"""The table of settings and what a change of each rebuilds (tests/data/settings_invalidation.csv),
shared by the suites that walk through it."""
import csv
import os

from pfv_testing import paths

TABLE = os.path.join(paths.TEST_DATA, "settings_invalidation.csv")


def rows():
    """The table's rows as dicts (lines starting with # are comments)."""
    with open(TABLE) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def change(target, name, value):
    """Set attribute `name` to `value`, or call method `name` with the tuple `value`."""
    member = getattr(target, name)
    if callable(member):
        member(*value)
    else:
        setattr(target, name, value)
