"""Reading and writing files: bounded reads of untrusted input (``inputs``), atomic
writes that never leave half a file (``files``), and YAML read safely (``safe_yaml``)."""
