"""Stepped studies: steady states (closed forms and time-domain engines) at each point of a parameter grid, any layout;
their pages (frequency responses, the bumper-stiffness convergence)."""
