//! The argument parser's errors as one sentence, like every other error of
//! the command line: the option, the value given and what it accepts,
//! instead of a usage block.

use clap::error::{ContextKind, ContextValue, ErrorKind};
use std::any::TypeId;

/// One sentence for a parse error of `cmd` (the whole command tree).
pub fn one_sentence(e: &clap::Error, cmd: &clap::Command) -> String {
    let text = |k| match e.get(k) {
        Some(ContextValue::String(s)) => Some(s.clone()),
        Some(ContextValue::Strings(v)) => Some(v.join(", ")),
        _ => None,
    };
    if matches!(e.kind(), ErrorKind::InvalidValue | ErrorKind::ValueValidation) {
        if let (Some(arg), Some(value)) = (text(ContextKind::InvalidArg), text(ContextKind::InvalidValue)) {
            let token = arg.split_whitespace().next().unwrap_or(&arg).to_string();
            // A positional argument is shown by its value name: "argument X".
            let name = match token.strip_prefix('<').and_then(|t| t.strip_suffix('>')) {
                Some(bare) => format!("argument {bare}"),
                None => token.clone(),
            };
            if value.is_empty() {
                return format!("{name} needs a value");
            }
            let accepted = match text(ContextKind::ValidValue).filter(|v| !v.is_empty()) {
                Some(valid) => Some(format!("one of {valid}")),
                None => find_arg(cmd, &token).and_then(accepted_values),
            };
            return match (accepted, std::error::Error::source(e)) {
                (Some(a), _) => format!("{name}: \"{value}\" is not {a}"),
                // A value parser of its own says why in its error.
                (None, Some(reason)) => format!("{name} {value}: {reason}"),
                (None, None) => format!("{name}: \"{value}\" is not a valid value"),
            };
        }
    }
    // A missing argument: clap lists the missing ones on the lines below
    // its first; they belong in the sentence.
    if e.kind() == ErrorKind::MissingRequiredArgument {
        if let Some(missing) = text(ContextKind::InvalidArg) {
            return format!("missing {missing}; see pinhole --help");
        }
    }
    // Other errors: clap's own first line is already one sentence.
    let rendered = e.render().to_string();
    let first = rendered.lines().next().unwrap_or("").trim_start_matches("error: ").trim();
    format!("{first}; see pinhole --help")
}

/// The argument an error names: `--long <VALUE>` by its long name,
/// `<NAME>` by its value name or id.
fn find_arg<'c>(cmd: &'c clap::Command, name: &str) -> Option<&'c clap::Arg> {
    let matches = |a: &clap::Arg| {
        if let Some(long) = name.strip_prefix("--") {
            a.get_long() == Some(long)
        } else {
            let bare = name.trim_start_matches('<').trim_end_matches('>');
            a.get_value_names().is_some_and(|v| v.iter().any(|n| n.as_str() == bare)) || a.get_id().as_str().eq_ignore_ascii_case(bare)
        }
    };
    cmd.get_arguments().find(|a| matches(a)).or_else(|| cmd.get_subcommands().find_map(|s| find_arg(s, name)))
}

/// What a numeric argument accepts, from its value type.
fn accepted_values(arg: &clap::Arg) -> Option<String> {
    let t = arg.get_value_parser().type_id();
    let whole = |max: u64| Some(format!("a whole number from 0 to {max}"));
    if t == TypeId::of::<u8>() {
        whole(u8::MAX as u64)
    } else if t == TypeId::of::<u16>() {
        whole(u16::MAX as u64)
    } else if t == TypeId::of::<u32>() {
        whole(u32::MAX as u64)
    } else if t == TypeId::of::<u64>() || t == TypeId::of::<usize>() {
        whole(u64::MAX)
    } else if t == TypeId::of::<i32>() || t == TypeId::of::<i64>() {
        Some("a whole number".into())
    } else if t == TypeId::of::<f32>() || t == TypeId::of::<f64>() {
        Some("a number".into())
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{CommandFactory, Parser};

    #[derive(Parser)]
    #[command(allow_negative_numbers = true)]
    struct T {
        x: u32,
        #[arg(long)]
        seed: Option<u64>,
    }

    #[test]
    fn negative_and_garbage_numbers_name_the_option_and_its_range() {
        let cmd = T::command();
        let e = T::try_parse_from(["t", "1", "--seed", "-1"]).err().unwrap();
        assert_eq!(one_sentence(&e, &cmd), "--seed: \"-1\" is not a whole number from 0 to 18446744073709551615");
        let e = T::try_parse_from(["t", "-1"]).err().unwrap();
        assert_eq!(one_sentence(&e, &cmd), "argument X: \"-1\" is not a whole number from 0 to 4294967295");
        let e = T::try_parse_from(["t", "1", "--seed"]).err().unwrap();
        assert_eq!(one_sentence(&e, &cmd), "--seed needs a value");
        let e = T::try_parse_from(["t", "1", "--nope"]).err().unwrap();
        let s = one_sentence(&e, &cmd);
        assert_eq!(s.lines().count(), 1, "{s}");
        assert!(s.contains("--nope"), "{s}");
    }

    #[test]
    fn a_missing_argument_is_named_in_the_sentence() {
        let e = T::try_parse_from(["t"]).err().unwrap();
        assert_eq!(one_sentence(&e, &T::command()), "missing <X>; see pinhole --help");
    }
}
