"""The plots and figures, drawn from the committed data. Matplotlib draws into files here, with
its Agg backend, chosen once for every plot: importing any module of this package selects it
before pyplot is imported (no display is needed, and none is opened)."""
import matplotlib

matplotlib.use("Agg")


def pyplot():
    """matplotlib.pyplot on the Agg backend, for a command outside this package that plots."""
    import matplotlib.pyplot as plt
    return plt
