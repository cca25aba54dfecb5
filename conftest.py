"""Doctest collection over the package: leave out the modules whose optional extra is not installed."""

import importlib.util

#: module needed -> package files that import it at module level
_NEEDS = {"stable_baselines3": ["collision_env/envs/sb3.py"]}

collect_ignore = [
    path for module, paths in _NEEDS.items() if importlib.util.find_spec(module) is None for path in paths
]
