"""The measurement runners: scaling, the regime sweep, the viewer's frame rate, PyAMG, meshes."""
