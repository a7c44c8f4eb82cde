"""``python -m slamtrials``: the same as the ``slamtrials`` command."""

from slamtrials.cli.main import main

if __name__ == "__main__":
    main()
