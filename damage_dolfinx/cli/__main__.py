"""``python -m damage_dolfinx.cli``: the command line."""
import sys

from damage_dolfinx.cli import main

sys.exit(main())
