"""meshgen: worm and wheel tooth geometry from gear data (ZI / ZA worm, enveloped wheel), watertight
meshes and the convex collision pieces MuJoCo needs."""
