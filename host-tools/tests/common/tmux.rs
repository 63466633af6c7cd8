//! A tmux session as a person's terminal: start a command in it, type keys, read the screen.

use std::process::Command;
use std::time::{Duration, Instant};

/// A tmux session (its own server socket), killed when dropped.
pub struct Tmux {
    socket: String,
}

impl Tmux {
    /// Runs `command` in a new 120 x 40 terminal whose locale is UTF-8 (as most desktops' are,
    /// whatever the environment the tests run in; a test that wants another sets its own).
    pub fn start(name: &str, command: &str) -> Tmux {
        let socket = format!("bowl-test-{name}-{}", std::process::id());
        let tmux = Tmux { socket };
        let args = [
            "new-session",
            "-d",
            "-x",
            "120",
            "-y",
            "40",
            "-e",
            "LC_ALL=C.UTF-8",
            command,
        ];
        let ok = tmux
            .cmd(&args)
            .status()
            .expect("tmux runs (tests/lib/ensure-tools.sh installs it)")
            .success();
        assert!(ok, "tmux new-session");
        tmux
    }

    pub fn cmd(&self, args: &[&str]) -> Command {
        let mut c = Command::new("tmux");
        c.args(["-L", &self.socket]).args(args);
        c
    }

    pub fn keys(&self, keys: &[&str]) {
        let mut args = vec!["send-keys", "-t", "0"];
        args.extend_from_slice(keys);
        assert!(self.cmd(&args).status().unwrap().success());
    }

    /// Resizes the window, as a person dragging the terminal's corner.
    pub fn resize(&self, columns: u16, rows: u16) {
        let (x, y) = (columns.to_string(), rows.to_string());
        let args = [
            "resize-window",
            "-t",
            "0",
            "-x",
            x.as_str(),
            "-y",
            y.as_str(),
        ];
        assert!(self.cmd(&args).status().unwrap().success(), "tmux resize");
    }

    pub fn screen(&self) -> String {
        let out = self
            .cmd(&["capture-pane", "-p", "-t", "0"])
            .output()
            .unwrap();
        String::from_utf8_lossy(&out.stdout).into_owned()
    }

    /// Waits until the screen shows every one of `texts`; fails with the screen otherwise.
    pub fn wait_for(&self, texts: &[&str], what: &str) -> String {
        self.wait_until(|screen| texts.iter().all(|t| screen.contains(t)))
            .unwrap_or_else(|screen| panic!("{what}: expected {texts:?} on the screen:\n{screen}"))
    }

    /// Waits until `text` shows `count` times on the screen (an answer like one seen before);
    /// fails with the screen otherwise.
    pub fn wait_for_count(&self, text: &str, count: usize, what: &str) -> String {
        self.wait_until(|screen| screen.matches(text).count() >= count)
            .unwrap_or_else(|screen| {
                panic!("{what}: expected {text:?} {count} times on the screen:\n{screen}")
            })
    }

    /// The screen once `done` holds for it, within 10 s; the last screen otherwise.
    fn wait_until(&self, done: impl Fn(&str) -> bool) -> Result<String, String> {
        let started = Instant::now();
        loop {
            let screen = self.screen();
            if done(&screen) {
                return Ok(screen);
            }
            if started.elapsed() >= Duration::from_secs(10) {
                return Err(screen);
            }
            std::thread::sleep(Duration::from_millis(200));
        }
    }
}

impl Drop for Tmux {
    fn drop(&mut self) {
        let _ = self.cmd(&["kill-server"]).status();
    }
}
