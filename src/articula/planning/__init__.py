"""Chapter 1 planning: reference trajectories, the objective of Eq. (1.13), BAORNN."""
