"""The --max-memory parser and the default memory budget."""

import os
import subprocess
import sys

import pytest

from rend3r.cliutil import default_memory, parse_bytes


@pytest.mark.parametrize("text, value", [("4G", 4 << 30), ("512M", 512 << 20), ("1.5GiB", 3 << 29),
                                         (" 2048 m ", 2 << 30), ("1T", 1 << 40), ("1048576", 1 << 20)])
def test_sizes(text, value):
    assert parse_bytes(text) == value


@pytest.mark.parametrize("text", ["", "G", "-1G", "1x", "0", "1K", "1e9", "1" * 5000, "١G", "1.2.3G"])
def test_bad_sizes_are_value_errors(text):
    with pytest.raises(ValueError):
        parse_bytes(text)


def test_default_budget_is_half_the_machine_and_follows_the_address_space_limit():
    assert 0 < default_memory() <= os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") // 2
    code = ("import resource; resource.setrlimit(resource.RLIMIT_AS, (3 << 30, resource.RLIM_INFINITY)); "
            "from rend3r.cliutil import default_memory; print(default_memory())")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert int(out) == min(2 << 30, default_memory())
