"""The virtual friction rig's Python side: `friction_sim.results` loads a run's results into numpy."""
