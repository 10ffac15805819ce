"""The contact3d MuJoCo template (worm_pair.xml), shipped as package data `wormsim.models`."""
