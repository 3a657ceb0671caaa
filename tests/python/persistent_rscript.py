"""One Rscript kept running for a test module's reference computations in R: R and its packages (lmerTest,
emmeans) load once, about 1.4-1.7 s of CPU each time, and the script answers every request of the module on
its standard input. Each test module gives its own script; `running()` starts it on first use (again if it
ended), `abandon()` kills one that answered wrong and `close()` ends it (registered with atexit)."""
import atexit
import os
import shutil
import subprocess
import tempfile


class PersistentRscript:
    def __init__(self, script: str, prefix: str):
        self._script = script
        self._prefix = prefix
        self._running = []  # (process, folder) while one runs
        atexit.register(self.close)

    def running(self):
        """(process, folder): the running Rscript (text pipes) and the temporary folder it runs from."""
        if self._running and self._running[0][0].poll() is None:
            return self._running[0]
        self.close()
        folder = tempfile.TemporaryDirectory(prefix=self._prefix)
        path = os.path.join(folder.name, "script.R")
        with open(path, "w", encoding="utf-8") as out:
            out.write(self._script)
        process = subprocess.Popen([shutil.which("Rscript"), "--vanilla", path], stdin=subprocess.PIPE,
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self._running.append((process, folder))
        return self._running[0]

    def abandon(self):
        """Kills the running Rscript (one that answered wrong or not at all) and forgets it; returns what it wrote
        on standard error."""
        process, folder = self._running.pop()
        process.kill()
        error = process.communicate()[1]
        folder.cleanup()
        return error

    def close(self):
        while self._running:
            process, folder = self._running.pop()
            if process.poll() is None:
                process.stdin.close()
                try:
                    process.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    process.kill()
                    process.wait()
            process.stdout.close()
            process.stderr.close()
            folder.cleanup()
