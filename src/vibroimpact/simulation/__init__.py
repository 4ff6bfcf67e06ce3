"""Time-domain results built on the engines: steady states at one frequency, harmonic measures, swept-sine runs."""
