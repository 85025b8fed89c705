"""The product's experiments: each one's config and run function, registered by name."""

from articula.experiments.plan import NAME, PLAN, PlanConfig, PlanSetup, build_plan, run_plan

__all__ = [
    "NAME",
    "PLAN",
    "PlanConfig",
    "PlanSetup",
    "build_plan",
    "motor",
    "plan",
    "pneunet",
    "run_plan",
    "six_chamber",
]
