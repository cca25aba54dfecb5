"""The speed/accuracy study (issue 5): what each mode costs, how far it is from exact, and where it breaks.

- :mod:`.scenes`: the benchmark scenes (PhET presets, gases, a corner shot, Newton's cradle, the pi
  billiard, an inelastic pile-up), each a function returning ``(scene, positions, velocities,
  masses, radii)``.
- :mod:`.metrics`: impact matching against the exact reference, conservation and validity checks,
  statistical checks for long runs.
- :mod:`.engines`: one stepping interface over this engine's modes and the peers (pymunk, billiards).
- :mod:`.sweep`: mode x control step x number of balls x scene, peers in the same run.
- :mod:`.extremes`: every mode over the stress grid (``python -m collision_env.bench.extremes``).
- :mod:`.stats`, :mod:`.envrates`, :mod:`.report`: long-run statistics, env steps per second, and
  the CSV / Markdown / plots / generated summary.

Run ``python -m collision_env.bench --quick`` (about half a minute) or without ``--quick`` (the
full study); outputs go to ``docs/bench/``.
"""
