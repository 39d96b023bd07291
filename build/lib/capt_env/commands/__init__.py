"""One module per ``capt`` verb: ``add_arguments(parser)`` and ``run(args) -> int``."""
