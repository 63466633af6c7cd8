//! `bowl ports`: the serial ports on this computer, with their USB descriptions.

/// Runs `bowl ports`.
pub fn run() -> anyhow::Result<()> {
    let ports = rig_client::serial::list_ports()?;
    if ports.is_empty() {
        println!(
            "no serial ports found (plug the rig in; a virtual rig: `bowl serve --pty`, whose \
             path it prints)"
        );
    }
    for p in ports {
        println!("{p}");
    }
    Ok(())
}
