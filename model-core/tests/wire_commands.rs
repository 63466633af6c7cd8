//! The command table's two readers agree and never panic: `Command::from_words` (what a person
//! types) and the rig's decoder (a command line with a good CRC), on random word lists built
//! from the table's own tokens, numbers of every sign and size, and junk.

use model_core::wire::crc::crc32;
use model_core::wire::*;
use proptest::prelude::*;

/// One word: a command token, a parameter or choice token, a number (negative, huge, with
/// leading zeros or `+`), or junk, in any case.
fn word() -> impl Strategy<Value = String> {
    let mut tokens: Vec<String> = CommandKind::ALL
        .iter()
        .map(|k| k.token().to_string())
        .collect();
    tokens.extend(ParamId::ALL.iter().map(|p| p.token().to_string()));
    tokens.extend(ResidenceModel::TOKENS.iter().map(|t| t.to_string()));
    tokens.extend(Injection::TOKENS.iter().map(|t| t.to_string()));
    let token = proptest::sample::select(tokens);
    prop_oneof![
        3 => (token, any::<bool>()).prop_map(|(t, lower)| if lower { t.to_ascii_lowercase() } else { t }),
        3 => any::<i64>().prop_map(|v| v.to_string()),
        3 => (-40_000i64..=40_000).prop_map(|v| v.to_string()),
        1 => (0u32..100).prop_map(|v| format!("0{v}")),
        1 => (0u32..100).prop_map(|v| format!("+{v}")),
        1 => "[ -~]{0,12}",
        1 => "[A-Z_0-9]{1,20}",
    ]
}

fn words() -> impl Strategy<Value = Vec<String>> {
    proptest::collection::vec(word(), 0..5)
}

/// The rig's verdict on the same words, sent as a command line with a good CRC (upper case,
/// as a line on the wire is). A person's words part at commas and at white space (`bowl send
/// PORT "speed 1800 2100"` as one argument), as the tools that send them part them.
fn rig_reads(words: &[String]) -> Result<Command, Reason> {
    let mut payload = String::from("C1,7");
    for w in words
        .iter()
        .flat_map(|w| w.split(|c: char| c == ',' || c.is_ascii_whitespace()))
        .filter(|w| !w.is_empty())
    {
        payload.push(',');
        payload.push_str(&w.to_ascii_uppercase());
    }
    let line = format!("{payload}*{:08X}", crc32(payload.as_bytes()));
    match parse_command_line(line.as_bytes()) {
        Ok(Frame::Command { id: 7, command }) => Ok(command),
        Err(FrameError::BadCommand { id: 7, reason }) => Err(reason),
        other => panic!("{line}: {other:?}"),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    /// Never a panic; a command taken is in range and survives the wire; a refusal has words
    /// and the reason the rig gives for the same line.
    #[test]
    fn from_words_agrees_with_the_rig(words in words()) {
        let typed = Command::from_words(&words);
        match typed {
            Ok(command) => {
                prop_assert!(command.in_range());
                let mut buf = [0u8; MAX_FRAME_LEN];
                let n = encode(&Frame::Command { id: 9, command }, &mut buf).unwrap();
                prop_assert_eq!(decode_frame(&buf[..n]), Ok(Frame::Command { id: 9, command }));
            }
            Err(refusal) => prop_assert!(!refusal.to_string().is_empty()),
        }
        // The only words the rig reads differently: junk that is a number to a person but not
        // to the rig (`+5`, `05`) and non-ASCII case folding; both are refused either way.
        let typed = typed.map_err(|r| r.reason());
        prop_assert_eq!(typed, rig_reads(&words), "{:?}", words);
    }

    /// Any command fields after a good header and CRC: the decoder never panics, and what it
    /// takes re-encodes to the same bytes.
    #[test]
    fn random_command_fields_never_panic_and_round_trip(
        id in any::<u16>(),
        fields in proptest::collection::vec(prop_oneof![word(), "[ -~]{0,8}"], 0..5),
    ) {
        let payload = format!("C1,{id},{}", fields.join(","));
        let line = format!("${payload}*{:08X}\r\n", crc32(payload.as_bytes()));
        if let Ok(frame) = decode_frame(line.as_bytes()) {
            let mut buf = [0u8; MAX_FRAME_LEN];
            let n = encode(&frame, &mut buf).unwrap();
            prop_assert_eq!(&buf[..n], line.as_bytes());
        }
    }
}

#[test]
fn every_example_of_the_table_is_taken() {
    for kind in CommandKind::ALL {
        let words: Vec<&str> = kind.example().split(' ').collect();
        let command = Command::from_words(&words).unwrap();
        assert_eq!(command.kind(), kind);
    }
}

#[test]
fn refusals_say_the_value_the_limit_and_the_names() {
    let said = |line: &str| {
        let words: Vec<&str> = line.split(' ').collect();
        Command::from_words(&words).unwrap_err().to_string()
    };
    assert!(said("speed -1 2100").contains("the precession speed -1 mrad/s is below 0"));
    assert!(said("speed -1 2100").contains("SPEED_MAX1_MRAD_S"));
    assert!(said("set TELEM_HZ 51").contains("TELEM_HZ 51 frames/s is outside its range 0..=50"));
    assert!(said("set FOO 1").contains("`FOO` is not a parameter; the parameters: RIM_UM"));
    // A switch is named as one: no unit "0/1" printed as if it were one.
    assert_eq!(
        said("set CUR_SENSE 2"),
        "CUR_SENSE is a switch: 0 (off) or 1 (on), not 2"
    );
    assert_eq!(
        said("set CUR_SENSE on"),
        "CUR_SENSE is a switch: 0 (off) or 1 (on), not `on`"
    );
    assert!(
        said("rtime fast 2500").contains("`fast` is not a residence model: flat, cori or table")
    );
    assert!(said("speed 1800").contains("`speed` takes 2 values after it, got 1"));
    assert!(said("speed 01800 2100").contains("write `01800` as `1800`"));
    assert!(said("jump").contains("`jump` is not a command; the commands: speed, rtime"));
    assert_eq!(
        Command::from_words(&["set", "telem_hz", "20"]),
        Ok(Command::SetParam {
            id: ParamId::TelemetryHz,
            value: 20
        })
    );
    assert_eq!(
        Command::from_words(&["speed,1500,2100"]),
        Ok(Command::SetSpeeds {
            precession_mrad_s: 1500,
            spin_mrad_s: 2100
        })
    );
}
