"""The fleet page's title and the page the book shows in its place where notebook 11 did not run (a profile without
a fleet): words only, so that the book's build (:mod:`bgfn.report.book_notebooks`) imports no study to write them."""

from __future__ import annotations


#: The fleet page's title (notebook 11's first line): the book's page says it when the study did not run.
FLEET_PAGE_TITLE = "11 Beyond the paper: a fleet of drives"


def no_fleet_line(profile: str) -> str:
    """What notebook 11 says for a profile that names no fleet."""
    return (f"Profile `{profile}` names no fleet (its `fleet.drives` is empty): the fleet study did not run. "
            "`make reproduce PROFILE=fleet` runs it on the shipped real drive cut into three pieces; a fleet of "
            "one's own drives is a profile's `fleet: {drives: [...]}` (README, *Your own log*).")


def absent_page(profile: str) -> str:
    """The book's fleet page (Markdown) for a profile whose chain has no ``fleet:`` section (notebook 11 did not
    run)."""
    return f"# {FLEET_PAGE_TITLE}\n\n{no_fleet_line(profile)}\n"
