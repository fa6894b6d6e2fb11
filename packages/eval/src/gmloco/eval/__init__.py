"""gmloco.eval."""
