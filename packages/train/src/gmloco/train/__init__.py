"""gmloco.train."""
