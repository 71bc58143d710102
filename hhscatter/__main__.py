"""``python -m hhscatter`` = the ``hhscatter`` command."""

import sys

from hhscatter.cli import main

sys.exit(main())
