"""The task's compiled kernels, one module per phase of a control step.

A control step of an env (a batch of scenes, one for the single env) is:

1. :mod:`~.nudge`: the actions become velocity changes of the controlled balls;
2. the engine steps every scene;
3. :mod:`~.finish`: the step's impacts are scored against the targets (:mod:`~.scoring`, whose
   walk over the impacts the prediction shares), the episodes advance, the observation is written
   (:mod:`~.observe`) and the episode-end flags and reward are settled (:mod:`~.episode_end`);
4. with ``observe="predicted"``, :mod:`~.predict` writes what a copy of the engine run ahead
   reports.

Resets draw start states with :mod:`~.episodes`. The task's packed arrays are named in
:mod:`~.layout` and handed to the kernels as named bundles (:mod:`~.arrays`); :mod:`~.checks` checks
a task state handed to ``set_state``.
"""
