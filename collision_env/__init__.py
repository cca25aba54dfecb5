"""collision_env: Gymnasium environments on a time-of-impact-correct ball collision engine."""

__version__ = "0.1.0"
