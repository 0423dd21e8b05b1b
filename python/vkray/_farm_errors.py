"""The farm's own kinds of failure, beside vkray's (SceneError, UsageError, DeviceError): each is one
class of the command line's exit codes, which ``vkray.farm.main`` maps them to."""


class _Usage(Exception):
    """An option's value the farm refuses: usage (2), as `vkray render` refuses a flag's."""


class _CannotWrite(Exception):
    """An output, or a part in the folder beside it, cannot be written: bad input (1)."""


class _MissingPackage(Exception):
    """A package the job needs is not importable by the Python that runs the farm (Dask's
    distributed, or pyoidn for --denoise): bad input (1)."""


class _ClusterError(Exception):
    """The cluster cannot do the job: no workers, none with a GPU, all of them lost (3)."""
