import sys

from twin_app.cli import main

sys.exit(main())
