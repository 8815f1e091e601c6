"""Command-line front end of masonry: parses, calls the library, reports."""
