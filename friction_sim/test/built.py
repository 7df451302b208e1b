"""Where the Python tests find what the build made."""
from catkin.find_in_workspaces import find_in_workspaces


def friction_run():
    """The built offline runner's path; an AssertionError (a test failure) if it is not built."""
    runners = find_in_workspaces(["libexec"], project="friction_sim", path="friction_run", first_match_only=True)
    if not runners:
        raise AssertionError("friction_run is not built")
    return runners[0]
