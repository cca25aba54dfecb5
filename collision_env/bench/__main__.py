"""``python -m collision_env.bench [section] [options]``: run one benchmark section (default: the study).

python -m collision_env.bench --quick                 # the study (as ``python -m collision_env.bench.study``)
python -m collision_env.bench engine --quick          # a section, as ``python -m collision_env.bench.engine``
python -m collision_env.bench --list                  # the sections
"""

from __future__ import annotations

import importlib
import sys

from . import SECTIONS


def section_list() -> str:
    width = max(map(len, SECTIONS))
    return "\n".join(f"  {name:<{width}}  {summary}" for name, (_, summary) in SECTIONS.items())


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["--list"]:
        print(f"sections (python -m collision_env.bench <section> --help):\n{section_list()}")
        return 0
    name = argv.pop(0) if argv and argv[0] in SECTIONS else "study"
    module = importlib.import_module(SECTIONS[name][0])
    return module.main(argv) or 0


if __name__ == "__main__":
    sys.exit(main())
