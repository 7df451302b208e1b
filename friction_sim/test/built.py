"""Where the Python tests find what the build made."""
from catkin.find_in_workspaces import find_in_workspaces


def program(name):
    """A built program of friction_sim's; an AssertionError (a test failure) if it is not built."""
    found = find_in_workspaces(["libexec"], project="friction_sim", path=name, first_match_only=True)
    if not found:
        raise AssertionError("%s is not built" % name)
    return found[0]


def friction_run():
    """The built offline runner's path."""
    return program("friction_run")
