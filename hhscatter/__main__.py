"""``python -m hhscatter`` = the ``hhscatter`` command."""
import sys

from .cli import main

sys.exit(main())
