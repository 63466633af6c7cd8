//! On the emulated board, across two self-inflicted resets: the reset counter counts them and
//! the parameter log (version + CRC-32 records) gives back what was saved before each reset.
//! Run: `cargo test -p firmware --no-default-features --test qemu_reset`.

use bowl_emulator::board::Board;
use bowl_emulator::image;

#[test]
fn reset_counter_and_parameters_survive_resets_under_qemu() {
    let elf = image::build("qemu-fw-reset").expect("the image builds");
    let (ok, console) = Board::boot(&elf).finish();
    let text = console.join("\n");
    println!("{text}");
    assert!(ok, "the board reported a failure:\n{text}");
    for name in [
        "boot0-no-record",
        "boot0-save",
        "boot1-loads-record-a",
        "boot1-save",
        "boot2-loads-record-b",
        "boot2-reset-count",
    ] {
        assert!(
            console.iter().any(|l| l == &format!("check {name} ok")),
            "check {name} did not pass:\n{text}"
        );
    }
}
