"""tg_drake: task-dependent robot grasping as a Drake systems diagram.

Pipeline (paper: Antanas et al., "High-level Reasoning and Low-level Learning for Grasping: A
Probabilistic Logic Pipeline"): perception → graph-kernel category prior → ProbLog reasoning over
category, task and part → local-shape (DGI + SVM) grasp scoring → iiwa + WSG execution.
"""

__version__ = "0.1.0"
