"""The one error type for bad user input: it names the file, the field or column, and the problem."""


class InputError(Exception):
    """A user's file or argument is wrong. The command line prints it on one line and exits 2.

    Parameters
    ----------
    source : str
        The file (or command-line option) the problem is in.
    field : str
        The field, column or key at fault ("components[3].layers", "T_out", "--force").
    problem : str
        What is wrong, in words a user can act on.
    """

    def __init__(self, source, field, problem):
        self.source = str(source)
        self.field = str(field)
        self.problem = str(problem)
        super().__init__(f"{self.source}: {self.field}: {self.problem}")
