"""Physics runs built from the cores: diagrams that are simulated, not stages of the pipeline.

- `episode`: one grasp executed by a free-floating WSG 50 (labels for the DGI's training data);
- `scripted`: a scripted grasp-and-lift in the station, with no perception or reasoning.

The cores (tg_drake.perception, kernels, logic, grasping, planning) never import this package.
"""
