import os
import sys

from .cli import main

code = main()
# Leave without the interpreter's teardown: pythonfmu's native side can call a logger callback
# that Python already freed while the interpreter shuts down ("corrupted double-linked list",
# an abort after every result was written). Everything is written and flushed by now.
sys.stdout.flush()
sys.stderr.flush()
os._exit(code or 0)
