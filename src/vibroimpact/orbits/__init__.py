"""Periodic orbits of the impacting system: shooting on the stroboscopic map with its exact Jacobian, pseudo-arclength
continuation with the detection of folds, period doublings, Neimark-Sacker and grazing points, and the Lyapunov
exponents of motion that is not periodic."""
