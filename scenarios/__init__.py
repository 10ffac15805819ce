"""The scenario files, shipped as package data `wormsim.scenarios` (the bench runs the seed scenarios from here)."""
