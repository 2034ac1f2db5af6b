"""The plots and figures, drawn from the committed data (matplotlib, Agg)."""
