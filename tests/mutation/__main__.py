"""``python -m tests.mutation``: see :mod:`tests.mutation.run`."""
import sys

from tests.mutation.run import main

sys.exit(main())
