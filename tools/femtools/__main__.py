"""`python -m femtools GROUP COMMAND`: the same as `fem-tools`."""
import sys

from femtools.cli import main

sys.exit(main())
