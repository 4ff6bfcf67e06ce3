"""Benchmark studies: what accuracy costs, every engine at every tolerance against a reference, the bumper-stiffness
ladder and the swept-sine cost comparison; their page."""
