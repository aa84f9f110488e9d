"""The bottom layer every other layer uses: errors, input validation, atomic file I/O.

``gearwear.core`` imports nothing from the rest of the package."""
