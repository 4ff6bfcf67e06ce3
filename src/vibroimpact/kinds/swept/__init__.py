"""Swept-sine studies: the compliant model run through whole sweeps (the paper's Simulink runs, section 5), against the
steady states; their page."""
