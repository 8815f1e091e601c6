"""Maintainers' benches and research studies (installed as ``masonry_benchmarks``):
leaves that call the library, kept out of it. ``masonry bench`` runs the benches
(:mod:`masonry_benchmarks.bench`, ``reader_bench``, ``output_bench``, ``stages_bench``);
``python -m masonry_benchmarks.revolution_study`` runs the study of domes with and without
the herringbone (docs/revolution.md)."""
