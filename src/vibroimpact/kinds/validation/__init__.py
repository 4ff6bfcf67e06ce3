"""Validation studies: one published closed form per scene, reproduced by the project's engines and continuation; their
page."""
