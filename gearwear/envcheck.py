"""Check that the Gmsh wheel can load its system libraries; print the fix if not."""

import sys

APT_LINE = "apt-get install libglu1-mesa libxrender1 libxcursor1 libxft2 libxinerama1"


def main() -> int:
    try:
        import gmsh  # noqa: F401
    except OSError as exc:  # missing shared library
        print(f"gearwear: gmsh cannot load a system library ({exc}); on Debian/Ubuntu run: {APT_LINE}", file=sys.stderr)
        return 1
    except ImportError as exc:
        print(f"gearwear: gmsh is not installed ({exc}); run `make demo` or `pip install -e .`", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
