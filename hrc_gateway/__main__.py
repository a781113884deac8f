"""`python -m hrc_gateway --name cobot1 ...`: the console script `hrc-gateway` by another name."""

import sys

from hrc_gateway.cli import main

sys.exit(main())
