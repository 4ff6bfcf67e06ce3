"""Physics only: the linear system, its modes, the excitations, the contact laws and the problem they compose.

Imports nothing of the package above it.
"""
