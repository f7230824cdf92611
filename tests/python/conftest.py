"""The `run` fixture: every run file under $MPMLAB_RESULTS, one at a time, each read once for
all the test modules.
"""

import pytest

from layout import RUN_FILES, Run, _file_id


@pytest.fixture(scope="session", params=RUN_FILES, ids=[_file_id(p) for p in RUN_FILES])
def run(request):
    return Run(request.param)
