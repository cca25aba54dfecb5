"""The physics every mode shares: times of impact, collision responses, motion between collisions,
contact tolerances and the least-distance solve of a contact group's limit."""
