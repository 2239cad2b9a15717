"""Output that never leaves half-written results behind, and progress on a terminal.

`paths`: what an output may not be (checked before any work); `atomic`: writing through a
temporary and a lock; `tables`: the CSV every table is written as; `progress`: the terminal line;
`provenance`: the software versions recorded beside results.
"""

from .atomic import atomic_directory, atomic_file, exclusive
from .paths import MANIFEST, check_file_names, check_option_values, check_outputs, command_inputs
from .progress import Progress, terminal_progress
from .provenance import software_versions
from .tables import INFINITE_OK, check_finite, write_table

__all__ = ["MANIFEST", "INFINITE_OK", "Progress", "atomic_directory", "atomic_file", "check_file_names",
           "check_finite", "check_option_values", "check_outputs", "command_inputs", "exclusive",
           "software_versions", "terminal_progress", "write_table"]
