import sys
from pathlib import Path

# the hand-derived facts in tests/hand are imported as a package
sys.path.insert(0, str(Path(__file__).parent))
