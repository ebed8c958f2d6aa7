"""The exceptions and warnings of restir_pt (raised by the native module by name)."""


class RestirPtError(Exception):
    """Any restir-pt failure; the message is the one line the CLI prints after ``error:``."""


class SceneError(RestirPtError):
    """A scene file that cannot be loaded (missing, malformed, unsupported)."""


class SettingsError(RestirPtError, ValueError):
    """A setting out of range or of the wrong kind (the CLI's validation message)."""


class DeviceError(RestirPtError, RuntimeError):
    """No Vulkan device, a lost device, out of device memory, or a failed kernel."""


class SceneWarning(UserWarning):
    """Odd but usable scene input (the loader's ``warning:`` lines)."""
