"""Exact mode: event-driven stepping to machine precision at any step (the scheduler, its event
calendar and its cell grid)."""
