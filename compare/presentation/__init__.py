"""What people and CI read: reports, plots, the summary, the dashboard and its history, JUnit, schemas,
progress bars, animations and the live view."""
