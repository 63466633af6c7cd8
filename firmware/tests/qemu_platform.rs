//! The emulated board's platform layer under QEMU: embassy timers against QEMU's own TIM2 model
//! and the instruction clock, concurrent tasks on the WFI executor, and bytes both ways over the
//! emulated USART1. Run: `cargo test -p firmware --no-default-features --test qemu_platform`.

use std::io::Write;

#[test]
fn platform_checks_pass_under_qemu() {
    let elf = bowl_emulator::image::build("qemu-fw-platform").expect("the image builds");
    let mut board = bowl_emulator::board::Board::boot(&elf);

    assert_eq!(board.read_usart_line(), "ready");
    board.usart.write_all(b"bowl rig 0123\n").unwrap();
    assert_eq!(board.read_usart_line(), "echo 3210 gir lwob 13");

    let (ok, console) = board.finish();
    let text = console.join("\n");
    println!("{text}");
    assert!(ok, "the board reported a failure:\n{text}");
    for name in [
        "instruction-clock",
        "timer-delay",
        "ticker-1khz",
        "concurrent-task",
        "usart-echo",
    ] {
        assert!(
            console
                .iter()
                .any(|l| l.starts_with(&format!("check {name} ok"))),
            "check {name} did not pass:\n{text}"
        );
    }
    assert!(!text.contains("FAILED"), "{text}");
}
