"""Arm planners, one control period at a time: BAORNN (Algorithm 1) and its improved
variant, the velocity-IK and QP baselines, the objective (1.13), reference paths and their
config tables. The closed loop over time is `articula.loops.tracking`."""
