"""Benchmarks: what each fidelity mode costs, how far it is from exact, and how it compares with its peers.

Every section is a module with a ``main(argv)``, runnable on its own
(``python -m collision_env.bench.<section>``) or through the package
(``python -m collision_env.bench <section> ...``); :data:`SECTIONS` lists them, and
``python -m collision_env.bench`` alone runs the study.

- :mod:`.study`: mode x control step x number of balls x scene, peers in the same run, plus the
  stress grid, long-run statistics and env rates; outputs go to ``docs/bench/``.
- :mod:`.engine`: exact mode against billiards on a gas, the cost per step of each mode against
  pymunk, batched against looped stepping.
- :mod:`.envs`: env steps per second of every registered id against Gymnasium's CartPole.
- :mod:`.extremes`: every mode over the stress grid.
- :mod:`.scale`: exact mode on hard-disk gases of 10^2 to 10^5 disks in frames: events per second,
  memory per disk, and the validity of each run.
- :mod:`.misses`: the cache lines an event of that gas misses, by array, counted on the Python path
  through a model of one cache (where the cost per event of a large gas comes from).
- :mod:`.physics`: a periodic hard-disk fluid against the published equation of state and
  Enskog's collision rate; events per second through the public API.
- :mod:`.chains`: event-chain Monte Carlo against exact-mode MD on one dense hard-disk state: events
  per CPU second and the CPU time to an error bar on the pressure.
- :mod:`.networks`: contact networks at e < 1 in exact mode (a row of 10^4 struck at one end, a
  pile under gravity nudges, a collapsing cluster, a cooling gas): ms per step, memory, the clock.
- :mod:`.compile`: the CPU seconds numba takes with empty caches: a first step, a first env step,
  every kernel.
- :mod:`.backend`: compiled kernels against plain Python (numba missing) on a gas and an env.

What they share:

- :mod:`.peers`: one adapter class per peer engine (pymunk, billiards) behind one interface;
  :mod:`.engines` adds this engine's modes to it.
- :mod:`.scenes` (the benchmark cases), :mod:`.metrics` (impact matching, conservation and
  validity checks), :mod:`.timing` (repeated timers), :mod:`.machine` (what a run ran on),
  :mod:`.readme` (the generated blocks of the README and the docs pages).
"""

#: section name -> (module, what it measures)
SECTIONS: dict[str, tuple[str, str]] = {
    "study": ("collision_env.bench.study", "error against cost: every mode and peer, every scene (docs/bench/)"),
    "engine": ("collision_env.bench.engine", "exact mode against billiards; cost per step against pymunk; batching"),
    "envs": ("collision_env.bench.envs", "env steps per second of every registered id against CartPole"),
    "extremes": ("collision_env.bench.extremes", "every mode over the stress grid"),
    "scale": ("collision_env.bench.scale", "exact mode on gases of 10^2 to 10^5 disks: events/s, memory, validity"),
    "misses": ("collision_env.bench.misses", "cache lines missed per event of a gas, by array (a cache model)"),
    "compile": ("collision_env.bench.compile", "CPU seconds numba takes with empty caches, per kernel family"),
    "backend": ("collision_env.bench.backend", "compiled kernels against plain Python: a 1000-disk gas, an env"),
    "physics": ("collision_env.bench.physics", "a periodic hard-disk fluid against the published equation of state"),
    "chains": ("collision_env.bench.chains", "event-chain Monte Carlo against MD: CPU time to an error bar"),
    "networks": ("collision_env.bench.networks", "contact networks at e < 1: ms per step, memory, the clock"),
}
