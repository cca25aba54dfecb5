"""Sample agents for collision_env: PPO training and evaluation with stable-baselines3.

* ``python -m agents.train_ppo --env CollisionEnv/OneBallTarget-v0`` trains PPO with the shipped
  hyperparameters (``agents/hyperparams/ppo.yml``) and writes one run folder.
* ``python -m agents.evaluate runs/<run>`` plays deterministic episodes and sets the policy beside
  a random and a scripted (exact-prediction) baseline, measured in the same run.
* ``python -m agents.main`` is the README's main job: train the default preset, then evaluate it.
* ``python -m agents.study`` answers "train cheap, evaluate exact?" and measures every preset.
* ``python -m agents.train_rllib`` trains PPO on Ray RLlib, locally or on a cluster (``--address``);
  ``agents.evaluate`` evaluates its run folders too.

Needs the ``train`` extra (stable-baselines3 with torch, tqdm, rich, tensorboard, pyyaml, imageio);
the RLlib trainer needs the ``distributed`` extra (Ray with RLlib).
"""
