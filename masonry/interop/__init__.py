"""Adapters that let other tools call masonry; each imports its tool, so each is imported
only by whoever uses it (``import masonry.interop.compas_dem``)."""
