# SPDX-License-Identifier: Apache-2.0
"""The one exception type the ima tool reports to its user as a single line."""


class ImaError(Exception):
    """An error the user can act on; the CLI prints its message and exits with `exit_code`.

    Exit code 2 means a usage or configuration error (as ima-ske uses it), 1 anything else.
    """

    def __init__(self, message: str, exit_code: int = 1) -> None:
        super().__init__(message)
        self.exit_code = exit_code
