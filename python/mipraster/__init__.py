"""mipraster: a CPU software rasterizer.

The renderer itself is C++ (the ``mipraster`` command installed next to this package); this
package is its Python side.
"""

__version__ = "0.1.0"
