"""``python -m bgfn.train --profile ...`` (:mod:`bgfn.train.cli`)."""

from bgfn.train.cli import main

main()
