"""The generated docs: the results tables, the lesson tables, the chapter diffs."""
