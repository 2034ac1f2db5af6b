"""Loading, checking and reading the results JSON (bench, scaling, regimes, viewer)."""
