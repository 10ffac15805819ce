"""tooth: the exact-flank tooth contact of a worm gear pair, without MuJoCo (meshgen, gear_theory, numpy/numba only).

gap.py (the worm thread's signed distance), trim.py (flank points the worm cuts), window.py (the mesh window's teeth),
grid.py (the wheel's flank grid and the default slice count), pose.py (the bodies' poses with assembly errors),
kernel.py (per step: the contacts, their slice weights and frames, packed in one compiled call), merge.py (one contact
per tooth flank), hertz.py (the contact pattern and Hertz pressure), mesh_stiffness.py (the zero-load TCA's k(theta)).
contact3d (MuJoCo) and torsional both build on it; it imports neither."""
