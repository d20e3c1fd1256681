"""``python -m studies.cli``: the same as the ``rmt`` console script."""
import sys

from studies.cli.main import main

sys.exit(main())
