"""The `nodeforce` command and `python -m nodeforce`: the command line (`nodeforce.cli`), imported
once the command runs. Each worker process a command starts (multiprocessing's "spawn", see
`runtime.lifetime`) imports the command's main script again: through this module that costs it
nothing, where importing the command line would load the whole API (some 2 s) into every worker
before its first task."""
import sys


def main(argv=None):
    from nodeforce.cli import main as command  # the command's own process only: the docstring
    return command(argv)


if __name__ == "__main__":
    sys.exit(main())
