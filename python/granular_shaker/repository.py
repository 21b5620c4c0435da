"""Where the harness (granular_shaker.validation, granular_shaker.reports) finds the data of the
granular-shaker repository: the case files and studies of validation/, the claims of
reference-data/, the status files and grid-study tables of verification/, and reports/, where
the published reports are written. The data stays in the repository (it is not part of the
package); a command names the repository with --repository DIR, by default the git top level
of the current directory.
"""
import os
import subprocess

# Files every repository of granular-shaker has; a folder without them is not one.
MARKERS = (os.path.join("validation", "studies.toml"),
           os.path.join("reference-data", "claims.toml"))


class RepositoryNotFound(Exception):
    """Neither --repository nor the current directory names a granular-shaker repository."""


def git_top_level(directory):
    """The top level of the git work tree holding `directory`, or None outside one."""
    try:
        result = subprocess.run(["git", "-C", directory, "rev-parse", "--show-toplevel"],
                                capture_output=True, text=True)
    except OSError:
        return None
    return result.stdout.strip() if result.returncode == 0 else None


def find_repository(explicit=None, directory=None):
    """The absolute path of the repository: `explicit` if given, else the git top level of
    `directory` (default: the current directory). RepositoryNotFound names what is wrong."""
    if explicit:
        root, origin = os.path.abspath(explicit), f"--repository {explicit}"
    else:
        directory = directory or os.getcwd()
        root, origin = git_top_level(directory), f"the git top level of {directory}"
        if root is None:
            raise RepositoryNotFound(
                f"{directory} is not inside a git work tree: name the granular-shaker "
                "repository with --repository DIR")
    missing = [m for m in MARKERS if not os.path.isfile(os.path.join(root, m))]
    if missing:
        raise RepositoryNotFound(
            f"{origin} ({root}) is not a granular-shaker repository: it has no "
            f"{' or '.join(missing)}; name the repository with --repository DIR")
    return root


def add_repository_option(parser):
    parser.add_argument("--repository", metavar="DIR",
                        help="the granular-shaker repository whose data (validation/, "
                             "reference-data/, verification/) is read and whose reports/ is "
                             "written (default: the git top level of the current directory)")


def repository_argument(parser, args):
    """The repository the parsed arguments name; a bad one is an argument error (exit 2)."""
    try:
        return find_repository(args.repository)
    except RepositoryNotFound as problem:
        parser.error(str(problem))


def fill_missing_paths(args, defaults):
    """`args` with every path in `defaults` ({option name: path}) that was left out set."""
    for name, path in defaults.items():
        if getattr(args, name) is None:
            setattr(args, name, path)
    return args
