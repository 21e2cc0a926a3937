"""`python -m plc_client` is the `plc` command."""
import sys

from .cli import main

sys.exit(main())
