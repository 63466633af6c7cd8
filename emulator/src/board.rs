//! A board under QEMU with its USART1 on a Unix socket, for tests: boots an image, reads and
//! writes its link, and collects its semihosting console. A test harness: it panics, with the
//! reason, when the emulator cannot be started or the board stops answering.

use std::io::{BufRead, BufReader, Read};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

use crate::qemu::{self, Profile, Serial};

/// A running emulated board: QEMU's stdout carries the semihosting console.
pub struct Board {
    /// The QEMU process (stdout: the semihosting console).
    pub child: Child,
    /// The board's USART1.
    pub usart: UnixStream,
    socket_path: PathBuf,
}

impl Board {
    /// Boots `elf` in virtual time ([`Profile::VirtualTime`]); QEMU waits (`server=on,wait=on`)
    /// until we have connected to its USART1, so no byte the board sends is lost.
    pub fn boot(elf: &Path) -> Board {
        Self::boot_with(elf, &[])
    }

    /// Boots `elf` with extra QEMU arguments (e.g. `-append seconds=30`).
    pub fn boot_with(elf: &Path, extra: &[&str]) -> Board {
        let socket_path = std::env::temp_dir().join(format!(
            "bowl-qemu-{}-{}.sock",
            std::process::id(),
            elf.file_name().unwrap().to_string_lossy()
        ));
        let _ = std::fs::remove_file(&socket_path);
        let serial = Serial::Socket(socket_path.clone());
        let child = qemu::command(elf, Profile::VirtualTime, &serial)
            .args(extra)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("qemu-system-arm is installed");
        let deadline = Instant::now() + Duration::from_secs(20);
        let usart = loop {
            match UnixStream::connect(&socket_path) {
                Ok(s) => break s,
                Err(_) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(20))
                }
                Err(e) => panic!("QEMU's USART socket never appeared: {e}"),
            }
        };
        usart
            .set_read_timeout(Some(Duration::from_secs(30)))
            .unwrap();
        Board {
            child,
            usart,
            socket_path,
        }
    }

    /// Reads one `\n`-terminated line from the USART (without the newline).
    pub fn read_usart_line(&mut self) -> String {
        let mut line = Vec::new();
        let mut byte = [0u8; 1];
        loop {
            let n = self.usart.read(&mut byte).expect("USART read");
            assert!(n == 1, "USART closed before a full line: {line:?}");
            if byte[0] == b'\n' {
                return String::from_utf8_lossy(&line).into_owned();
            }
            line.push(byte[0]);
        }
    }

    /// Waits for QEMU to exit and returns (exit success, console lines).
    pub fn finish(mut self) -> (bool, Vec<String>) {
        let stdout = self.child.stdout.take().unwrap();
        let lines: Vec<String> = BufReader::new(stdout)
            .lines()
            .map_while(Result::ok)
            .collect();
        let status = self.child.wait().expect("QEMU exits");
        (status.success(), lines)
    }
}

impl Drop for Board {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = std::fs::remove_file(&self.socket_path);
    }
}
