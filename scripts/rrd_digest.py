"""A digest of what a Rerun recording holds, independent of how it was
chunked and of the ids and wall-clock times Rerun stamps on each write:
every entity's rows on each timeline, with RowIds and `log_time` dropped,
hashed in time order. The provenance is read without the commit and the
command line (which name the build and the output path). Two recordings of
the same seeded run give the same digest.

usage: python rrd_digest.py FILE.rrd [TIMELINE ...]   (default: sim_time latency)
"""

import hashlib
import json
import sys

if __name__ == "__main__" and {"-h", "--help"} & set(sys.argv[1:]):
    print(__doc__.strip())
    sys.exit(0)


import rerun as rr


def values(column: str, cells: list) -> list:
    """A column's cells; the provenance without its commit and command."""
    if not column.startswith("/errp/provenance:") or not column.endswith(":text"):
        return cells
    out = []
    for cell in cells:
        if cell:
            doc = json.loads(cell[0])
            doc.pop("commit", None)
            doc.pop("command", None)
            cell = [json.dumps(doc, sort_keys=True)]
        out.append(cell)
    return out


def digest(path: str, timelines: list[str]) -> str:
    store = rr.experimental.RrdReader(path).stream().collect()
    h = hashlib.sha256()
    for index in timelines:
        try:
            table = store.reader(index=index, contents="/**").to_arrow_table()
        except Exception:  # the timeline is not in this recording
            continue
        columns = sorted(
            c for c in table.column_names if "log_time" not in c and "RowId" not in c
        )
        rows = sorted(
            zip(*(map(repr, values(c, table.column(c).to_pylist())) for c in columns))
        )
        h.update(repr((index, columns, rows)).encode())
    return h.hexdigest()


if __name__ == "__main__":
    timelines = sys.argv[2:] or ["sim_time", "latency"]
    print(digest(sys.argv[1], timelines))
