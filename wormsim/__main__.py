"""`python -m wormsim ...`: the `wormsim` console script (wormsim.cli), also from a source checkout."""

import sys

from wormsim.cli import main

sys.exit(main())
