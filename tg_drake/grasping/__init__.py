"""grasping stage."""
