"""`python3 -m granular_shaker.validation`: the validation study (its command line: .cli)."""
import sys

from granular_shaker.validation.cli import main

sys.exit(main())
