"""The process around the code: jit_cache (the compiled kernels' cache, one per machine), prewarm (the writers'
imports in a background thread while a simulation runs), data (where models/ and scenarios/ are, installed or not)."""
