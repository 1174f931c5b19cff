"""Shared by the Cyclone DDS test peers."""
import sys
import time


def wait_matched(writers, timeout_s, who):
    """Waits until each writer has a matched subscription; exits naming `who` after timeout_s.

    A reliable, volatile writer drops what it writes before a reader has matched: a peer that
    counts what it sent must not start before this returns."""
    deadline = time.time() + timeout_s
    while any(w.get_publication_matched_status().current_count == 0 for w in writers):
        if time.time() > deadline:
            sys.exit(f"{who}: no subscriber matched within {timeout_s} s")
        time.sleep(0.05)
