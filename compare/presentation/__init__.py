"""What people and CI read: reports, plots, the summary, the dashboard and its history, JUnit, schemas,
progress bars, animations and the live view."""

from gearcheck.shared.public import public  # noqa: E402

# the public names: the order-tracking figures
__all__, __getattr__, __dir__ = public(__name__, {"order_plot": "order_plots", "waterfall_plot": "order_plots"})
