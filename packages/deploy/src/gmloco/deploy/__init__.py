"""gmloco.deploy."""
