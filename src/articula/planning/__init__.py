"""Arm planners, one control period at a time: BAORNN (Algorithm 1) and its improved
variant, the velocity-IK and QP baselines, the objective (1.13), reference paths and their
config tables. The closed loop over time is `articula.loops.tracking`."""

# The public modules (imported by name, not here: `import articula` stays light).
__all__ = [
    "approach",
    "baornn",
    "baornn_improved",
    "baornn_kernel",
    "clearance",
    "config",
    "config_files",
    "newton_step",
    "objective",
    "planner",
    "qp_ik",
    "rate_limits",
    "reach",
    "reference_velocity",
    "resolved_rate",
    "slide",
    "target_path",
    "task",
    "trajectories",
    "velocity_ik",
]
