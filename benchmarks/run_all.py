"""Run every ``benchmarks/bench_*.py`` (its ``main()``), or those named on the command line.

``--readme`` runs only the parts that feed README.md's speed table (``speed_table.py``; ``--write`` puts the table
into README.md; naming parts, e.g. ``--readme dynamics rcube``, runs those only)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

HERE = Path(__file__).parent


def main(names: list[str]) -> None:
    for path in sorted(HERE.glob("bench_*.py")):
        if names and path.stem.removeprefix("bench_") not in names:
            continue
        spec = importlib.util.spec_from_file_location(path.stem, path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        print(f"== {path.stem}", flush=True)
        module.main()


if __name__ == "__main__":
    if "--readme" in sys.argv[1:]:
        sys.path.insert(0, str(HERE))
        from speed_table import main as speed_table

        speed_table([a for a in sys.argv[1:] if a != "--readme"])
    else:
        main(sys.argv[1:])
