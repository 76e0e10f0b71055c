"""``python -m scenarios.cli``: the command line in one process (figures drawn in this process)."""
import sys

from scenarios.cli.commands import main

sys.exit(main())
