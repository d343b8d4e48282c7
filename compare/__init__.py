"""Alignment, metrics, reports and the command line."""
