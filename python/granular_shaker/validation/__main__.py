"""`python3 -m granular_shaker.validation`: the validation study (its command line: .cli)."""
import sys

from .cli import main

sys.exit(main())
