# Configuration of every IPython kernel of the project's venv: `make venv` copies this file to
# .venv/etc/ipython/ipython_kernel_config.py (IPython reads <sys.prefix>/etc/ipython/), so it touches no
# user-wide setting.
#
# papermill talks to its kernel over TCP on 127.0.0.1 (jupyter_client's default), and ipykernel warns about
# that at every kernel start ("Kernel is running over TCP without encryption ..."): six times a
# `make reproduce`, in the middle of the progress lines. This filter drops that one message; every other
# message of the kernel still reaches the log.
import logging


class _WithoutTcpWarning(logging.Filter):
    def filter(self, record: logging.LogRecord) -> bool:
        return "Kernel is running over TCP without encryption" not in record.getMessage()


logging.getLogger("IPKernelApp").addFilter(_WithoutTcpWarning())
