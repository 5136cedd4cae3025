"""The explorer's error: a run that stopped part-way."""


class RunError(RuntimeError):
    """A run stopped part-way (Newton failure); ``result`` holds the steps it completed."""

    def __init__(self, message: str, result):
        super().__init__(message)
        self.result = result
