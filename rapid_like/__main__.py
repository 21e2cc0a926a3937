"""`python -m rapid_like run PROGRAM.mod ...`: the same as the `rapid` console script."""
import sys

from .cli import main

sys.exit(main())
