"""A headless browser's temporary profile is removed even while a helper process the
browser left behind is still writing into it (chromium's crashpad and GPU processes outlive
the browser by a moment: the removal raced them, "Directory not empty", and failed a browser
test now and then), and a browser's whole process group ends with it. No browser needed:
a Python stand-in plays the browser and its straggling helper.
"""

from __future__ import annotations

import subprocess
import sys
import time

from pinmech.draw.browser import chromium_profile, end_process_group, remove_profile

#: A "browser" that starts a helper writing new files into the profile as fast as it can
#: for `seconds`, then exits at once, leaving the helper running (as chromium's may).
STRAGGLER = """
import os, subprocess, sys
folder, seconds = sys.argv[1], sys.argv[2]
helper = ("import os, sys, time\\n"
          "end = time.monotonic() + float(sys.argv[2]); k = 0\\n"
          "while time.monotonic() < end:\\n"
          "    d = os.path.join(sys.argv[1], 'Default')\\n"
          "    try:\\n"
          "        os.path.isdir(d) or os.mkdir(d); open(os.path.join(d, f'{k}.tmp'), 'w').close(); k += 1\\n"
          "    except OSError:\\n"
          "        pass\\n")
subprocess.Popen([sys.executable, "-c", helper, folder, seconds])
"""


def test_a_profile_still_written_by_a_straggling_helper_is_removed():
    with chromium_profile(prefix="pinmech-test-profile-") as folder:
        browser = subprocess.run([sys.executable, "-c", STRAGGLER, str(folder), "0.5"], check=True)
        assert browser.returncode == 0
        time.sleep(0.05)  # the helper is writing now
    assert not folder.exists()


def test_ending_a_browser_ends_the_helpers_it_started(tmp_path):
    (tmp_path / "profile").mkdir()
    browser = subprocess.Popen([sys.executable, "-c", STRAGGLER + "import time; time.sleep(60)\n",
                                str(tmp_path / "profile"), "60"], start_new_session=True)
    deadline = time.monotonic() + 10
    while not (tmp_path / "profile" / "Default").exists() and time.monotonic() < deadline:
        time.sleep(0.01)
    started = time.monotonic()
    end_process_group(browser, timeout_s=5)
    assert browser.poll() is not None and time.monotonic() - started < 5  # SIGTERM was enough
    written = len(list((tmp_path / "profile" / "Default").iterdir()))
    time.sleep(0.2)
    assert len(list((tmp_path / "profile" / "Default").iterdir())) == written  # the helper is gone too
    remove_profile(tmp_path / "profile", within_s=1)
    assert not (tmp_path / "profile").exists()


def test_removing_a_profile_that_is_already_gone_is_quiet(tmp_path):
    remove_profile(tmp_path / "never-made", within_s=0.1)
