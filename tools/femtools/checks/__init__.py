"""The repository's checks (ctest, CI): sizes, chapter sources, doc numbers, vectorization, warnings."""
