"""The Kelvin-Voigt bumper model (eq. 25) through SUNDIALS IDA, CVODE and ``solve_ivp``."""
