"""gmloco.contact."""
