"""TODO sim"""
