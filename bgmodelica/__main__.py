"""``python -m bgmodelica``: the command line (:func:`bgmodelica.cli.main`)."""

import sys

from .cli import main

sys.exit(main())
