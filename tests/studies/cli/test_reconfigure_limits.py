"""The limits `rmt compose` states in its help (kept in studies.cli.reconfigure so that `rmt --help`
imports no design module) are the library's own."""
from design.compose import reconfigure as lib
from studies.cli import reconfigure as cli


def test_the_cli_states_the_librarys_limits():
    assert (cli.MAX_K, cli.MAX_SWAP_COST) == (lib.MAX_K, lib.MAX_SWAP_COST)
