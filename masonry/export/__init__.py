"""Exporters, one module per format. Each turns arrays into bytes; :mod:`masonry.runfolder`
is the one place that writes files."""
